//! `pdeshape` for Python: scenes, exact evaluation and meshes as numpy arrays.
//!
//! A thin layer over `pdeshape-io` (scene files, diagnostics, exporters) and
//! `pdeshape-core` (the solved patches): no mathematics of its own. Every evaluation is the
//! library's, so `Patch.evaluate` equals `pdeshape sample` bit for bit. Solves and
//! evaluations run with the GIL released; evaluation results are written straight into the
//! buffer numpy takes over (no copy), meshes are copied once out of the core's `Vec3`s.

use numpy::ndarray::{Array1, Array2, Array4, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray4, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pdeshape_core::Vec3;
use pdeshape_core::limits::{Cap, Limits};
use pdeshape_core::mesh::Mesh as CoreMesh;
use pdeshape_core::patch::Surface;
use pdeshape_io::export::{Format, write_atomic, write_meshes};
use pdeshape_io::model;
use pdeshape_io::sample::{Target, points_into};
use pdeshape_io::scene::{ImportRoot, LoadOptions, Scene as IoScene, SceneError as IoSceneError, ScenePatch};
use pyo3::exceptions::{
    PyException, PyKeyError, PyMemoryError, PyRuntimeError, PyTimeoutError, PyTypeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyTuple};
use std::borrow::Cow;
use std::sync::Arc;

mod pool;
mod toml_text;

/// The allocator of the `pdeshape` binary (for the Rust side's allocations only), so that
/// evaluations cost what they cost there.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

pyo3::create_exception!(
    pdeshape,
    SceneError,
    PyException,
    "A scene that cannot be loaded: `str(e)` is the CLI's message; `e.file`, `e.line`, \
     `e.column` (1-based, or None) and `e.key` (dotted key path) give the place."
);

/// `pdeshape.notebook.show(obj, ...)`: the view is drawn by the Python side's widget code.
fn notebook_show<'py>(
    obj: &Bound<'py, PyAny>,
    resolution: Option<(usize, usize)>,
    width: i64,
    height: i64,
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("resolution", resolution)?;
    kwargs.set_item("width", width)?;
    kwargs.set_item("height", height)?;
    py.import("pdeshape.notebook")?.getattr("show")?.call((obj,), Some(&kwargs))
}

/// A message as Python users read it: the CLI's advice "raise the cap with `--limit
/// NAME=VALUE` (library: `Limits::NAME`)" becomes "pass `limits={'NAME': VALUE}`".
fn py_message(s: &str) -> String {
    const CLI: &str = "raise the cap with `--limit ";
    let Some(k) = s.find(CLI) else { return s.to_string() };
    let rest = &s[k + CLI.len()..];
    let Some(end) = rest.find('`') else { return s.to_string() };
    let Some((name, value)) = rest[..end].split_once('=') else { return s.to_string() };
    let mut tail = &rest[end + 1..];
    if let Some(t) = tail.strip_prefix(" (library: `Limits::") {
        tail = t.find("`)").map_or(tail, |i| &t[i + 2..]);
    }
    format!(
        "{}raise the cap with `limits={{'{name}': {value}}}` (a keyword of Scene.load and Scene.from_toml){tail}",
        &s[..k]
    )
}

fn scene_error(mut e: IoSceneError) -> PyErr {
    e.message = py_message(&e.message);
    Python::attach(|py| {
        let err = SceneError::new_err(py_message(&e.to_string()));
        let v = err.value(py);
        let set = |k: &str, x: Py<PyAny>| v.setattr(k, x).expect("exception attributes are settable");
        set("file", e.file.clone().into_pyobject(py).expect("str").into_any().unbind());
        set("line", e.line.into_pyobject(py).expect("int").into_any().unbind());
        set("column", e.column.into_pyobject(py).expect("int").into_any().unbind());
        set("key", e.key.clone().into_pyobject(py).expect("str").into_any().unbind());
        set("message", e.message.clone().into_pyobject(py).expect("str").into_any().unbind());
        err
    })
}

/// A loaded, solved scene (immutable: `set` returns a new one).
///
/// >>> s = pdeshape.Scene.load("examples/klein-bottle.toml")
/// >>> s.parameters["a"]
/// {'value': 1.0, 'min': 0.3, 'max': 3.0, 'step': None, 'expr': None, 'description': None}
/// >>> s.set(a=1.37).patches[0].evaluate(numpy.array([[0.5, 0.0]]))
#[pyclass(frozen, module = "pdeshape")]
struct Scene {
    inner: Arc<IoScene>,
    opts: LoadOptions,
    /// Seconds a solve or a mesh may take (0: no limit).
    time_limit: f64,
}

/// The default time limit of solves and meshes, as the CLI's.
const DEFAULT_TIME_LIMIT: f64 = 600.0;

/// Runs `f` without the GIL under the time limit (`seconds`, 0: none): past it the
/// computation stops at its next checkpoint and `TimeoutError` is raised.
fn limited<T: Send>(py: Python<'_>, seconds: f64, what: &str, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    if seconds <= 0.0 {
        return Ok(pool::detached(py, f));
    }
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    py.detach(|| pdeshape_core::cancel::within(std::time::Duration::from_secs_f64(seconds), threads, f)).map_err(|_| {
        PyTimeoutError::new_err(format!(
            "{what} ran past the time limit of {seconds} s and was stopped; pass time_limit=SECONDS to Scene.load or Scene.from_toml (0: no limit)"
        ))
    })
}

/// A time limit given to `Scene.load`/`from_toml`: finite and not negative.
fn time_limit(t: Option<f64>) -> PyResult<f64> {
    match t {
        None => Ok(DEFAULT_TIME_LIMIT),
        Some(t) if t.is_finite() && t >= 0.0 => Ok(t),
        Some(t) => Err(PyValueError::new_err(format!("time_limit = {t}: seconds, 0 or more (0: no limit)"))),
    }
}

impl Scene {
    fn build(
        text: &str,
        file: &str,
        name: &str,
        opts: LoadOptions,
        time_limit: f64,
        py: Python<'_>,
    ) -> PyResult<Scene> {
        let inner =
            limited(py, time_limit, "the solve", || IoScene::parse_with(text, file, name, &opts).map_err(Box::new))?
                .map_err(|e| scene_error(*e))?;
        Ok(Scene { inner: Arc::new(inner), opts, time_limit })
    }

    fn options(
        solver: Option<String>,
        terms: Option<usize>,
        limits: Option<&Bound<'_, PyDict>>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<LoadOptions> {
        let mut opts = LoadOptions { solver, terms, limits: Limits::default(), ..Default::default() };
        if let Some(l) = limits {
            for (k, v) in l.iter() {
                let name: String =
                    k.extract().map_err(|_| PyTypeError::new_err("limits: the keys are cap names (str)"))?;
                let cap: Cap = name.parse().map_err(|e: String| PyValueError::new_err(format!("limits: {e}")))?;
                let value: usize = v
                    .extract()
                    .map_err(|_| PyTypeError::new_err(format!("limits['{name}']: expected a non-negative integer")))?;
                opts.limits.set(cap, value);
            }
        }
        if let Some(p) = params {
            for (k, v) in p.iter() {
                let name: String = k.extract()?;
                let value: f64 =
                    v.extract().map_err(|_| PyTypeError::new_err(format!("parameter `{name}`: expected a number")))?;
                if !value.is_finite() {
                    return Err(PyValueError::new_err(format!("parameter `{name}` = {value} is not finite")));
                }
                opts.params.insert(name, value);
            }
        }
        Ok(opts)
    }
}

#[pymethods]
impl Scene {
    /// A scene built from Python values in the scene file's vocabulary: each keyword is a
    /// top-level table of a scene file (`scene`, `parameters`, `curves`, `surfaces`,
    /// `patches`, `render`, `output`, `studies`) given as dicts, lists, numbers, strings
    /// and numpy arrays; `Scene(**tomllib.load(f))` is the scene of file `f`.
    ///
    /// >>> ring = numpy.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    /// >>> pdeshape.Scene(
    /// ...     curves={"bottom": pdeshape.bspline(ring, closed=True),
    /// ...             "top": pdeshape.bspline(ring + [0, 0, 1], closed=True)},
    /// ...     patches={"tube": pdeshape.pde(conditions=[{"u": 0, "curve": "bottom"},
    /// ...                                               {"u": 1, "curve": "top"}])})
    ///
    /// The values are written as scene text (`to_toml` returns it) and that text is parsed
    /// and solved, so the scene equals the one its text describes bit for bit. Errors name
    /// the argument and the index (`curves.top.bspline[2][0] = nan is not finite`) or, for
    /// what the scene itself rejects, the key (`SceneError.key`). `name`, `solver`,
    /// `terms`, `limits` and `time_limit` are as in `from_toml`.
    #[new]
    #[pyo3(signature = (*, name="scene", solver=None, terms=None, limits=None, time_limit=None, **tables))]
    fn new(
        py: Python<'_>,
        name: &str,
        solver: Option<String>,
        terms: Option<usize>,
        limits: Option<&Bound<'_, PyDict>>,
        time_limit: Option<f64>,
        tables: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let text = match tables {
            Some(t) => {
                let opts = Scene::options(None, None, limits, None)?;
                toml_text::scene_text(t, &mut toml_text::Budget::new(&opts.limits))?
            }
            None => String::new(),
        };
        Scene::from_toml(py, &text, name, solver, terms, limits, time_limit, None)
    }

    /// The scene text this scene was solved from, with the values given to `set` (or as
    /// keywords of `load`) written into its `[parameters]`: `Scene.from_toml(s.to_toml())`
    /// is `s` bit for bit. `solver`, `terms`, `limits` and `time_limit` are options of the
    /// load, not part of the text.
    fn to_toml(&self) -> PyResult<String> {
        pdeshape_io::scene::edit::with_parameters(&self.inner.source, &self.inner.options.params)
            .map_err(PyRuntimeError::new_err)
    }

    /// Pickling: the scene's text, name and load options; unpickling solves it again
    /// (deterministic: the same arrays bit for bit), so scenes go to `multiprocessing`,
    /// `concurrent.futures`, Dask and Ray workers.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let restore = py.import("pdeshape._native")?.getattr("_scene_from_state")?;
        Ok((restore, PyTuple::new(py, [scene_state(py, &self.inner, self.time_limit)?])?))
    }

    /// An interactive 3D view in Jupyter (a pythreejs widget; `pip install pythreejs`):
    /// see `pdeshape.notebook.show`.
    #[pyo3(signature = (*, resolution=None, width=800, height=600))]
    fn show<'py>(
        slf: &Bound<'py, Self>,
        resolution: Option<(usize, usize)>,
        width: i64,
        height: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        notebook_show(slf.as_any(), resolution, width, height)
    }

    /// The scene drawn as `pdeshape render` draws it (PNG bytes): Jupyter shows it.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let scene = self.inner.clone();
        let img = limited(py, self.time_limit, "the picture", move || model::render_scene(&scene))?
            .map_err(PyRuntimeError::new_err)?;
        png_bytes(py, &img)
    }

    /// Loads and solves a scene file. Keyword arguments override parameters
    /// (`Scene.load(path, a=1.37)`); `solver` ("auto", "exact", "collocation") and `terms`
    /// override blends' solvers as the CLI's `--solver` and `--terms` do; `limits` sets caps
    /// as the CLI's `--limit` does (`limits={"memory": 1024, "modes": 1024}`; names: order,
    /// modes, collocation, vertices, memory in MiB, scene in MiB). The memory cap also
    /// bounds the arrays `evaluate` and `derivatives` return. `time_limit` (seconds, default
    /// 600 as in the CLI, 0: none) bounds the solve and every mesh: past it they stop and
    /// raise `TimeoutError`.
    #[staticmethod]
    #[pyo3(signature = (path, *, solver=None, terms=None, limits=None, time_limit=None, **params))]
    fn load(
        py: Python<'_>,
        path: std::path::PathBuf,
        solver: Option<String>,
        terms: Option<usize>,
        limits: Option<&Bound<'_, PyDict>>,
        time_limit: Option<f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let time_limit = self::time_limit(time_limit)?;
        let mut opts = Scene::options(solver, terms, limits, params)?;
        opts.imports = import_folder(&pdeshape_io::scene::scene_folder(&path))?;
        let text = pdeshape_io::scene::read_scene_file(&path, &opts.limits).map_err(scene_error)?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
        Scene::build(&text, &path.display().to_string(), &name, opts, time_limit, py)
    }

    /// Parses and solves scene text (TOML); `name` labels errors and exports. The text is
    /// held to the `scene` cap as files are (16 MiB unless `limits` says otherwise). Its
    /// `[import.*]` paths are relative to the current directory (`Scene.load`: to the scene
    /// file's folder).
    #[staticmethod]
    #[pyo3(signature = (text, name="scene", *, solver=None, terms=None, limits=None, time_limit=None, **params))]
    #[allow(clippy::too_many_arguments)]
    fn from_toml(
        py: Python<'_>,
        text: &str,
        name: &str,
        solver: Option<String>,
        terms: Option<usize>,
        limits: Option<&Bound<'_, PyDict>>,
        time_limit: Option<f64>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Scene> {
        let time_limit = self::time_limit(time_limit)?;
        let mut opts = Scene::options(solver, terms, limits, params)?;
        opts.imports = import_folder(std::path::Path::new("."))?;
        opts.limits
            .check(Cap::Scene, (text.len() as u128).div_ceil(1 << 20), "the scene text's size")
            .map_err(|e| SceneError::new_err(py_message(&format!("{name}: {e}"))))?;
        Scene::build(text, name, name, opts, time_limit, py)
    }

    /// A new scene with parameters changed (`scene.set(a=1.37)`), solved again.
    #[pyo3(signature = (**values))]
    fn set(&self, py: Python<'_>, values: Option<&Bound<'_, PyDict>>) -> PyResult<Scene> {
        let mut opts = self.opts.clone();
        opts.params.extend(Scene::options(None, None, None, values)?.params);
        let s = &self.inner;
        Scene::build(&s.source, &s.file, &s.name, opts, self.time_limit, py)
    }

    /// The parameters in file order: name → {value, min, max, step, expr, description}.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, p) in &self.inner.params {
            let e = PyDict::new(py);
            e.set_item("value", p.value)?;
            e.set_item("min", p.min)?;
            e.set_item("max", p.max)?;
            e.set_item("step", p.step)?;
            e.set_item("expr", p.expr.clone())?;
            e.set_item("description", p.description.clone())?;
            d.set_item(name, e)?;
        }
        Ok(d)
    }

    /// The patches in file order.
    #[getter]
    fn patches(&self) -> Vec<Patch> {
        (0..self.inner.patches.len())
            .map(|index| Patch { scene: self.inner.clone(), index, time_limit: self.time_limit })
            .collect()
    }

    /// The patch called `name` (KeyError names the patches there are).
    fn patch(&self, name: &str) -> PyResult<Patch> {
        match self.inner.patches.iter().position(|p| p.name == name) {
            Some(index) => Ok(Patch { scene: self.inner.clone(), index, time_limit: self.time_limit }),
            None => Err(PyKeyError::new_err(format!(
                "no patch named `{name}` (patches: {})",
                self.inner.patches.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
            ))),
        }
    }

    fn __getitem__(&self, name: &str) -> PyResult<Patch> {
        self.patch(name)
    }

    fn __len__(&self) -> usize {
        self.inner.patches.len()
    }

    /// The file label (path, or the name given to `from_toml`).
    #[getter]
    fn file(&self) -> &str {
        &self.inner.file
    }

    /// `[scene] title`.
    #[getter]
    fn title(&self) -> Option<&str> {
        self.inner.title.as_deref()
    }

    /// The scene's diagnostics: the same report as `pdeshape check --json`, as a dict.
    fn check<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let scene = self.inner.clone();
        let text = pool::detached(py, move || serde_json::to_string(&model::scene_diagnostics(&scene)))
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// Writes every patch's mesh to `path` in the format of its extension (obj, ply, stl,
    /// gltf, glb, vtu, ...) or `format`, atomically, as `pdeshape build -o` does; `.png`
    /// renders the scene.
    #[pyo3(signature = (path, format=None))]
    fn export(&self, py: Python<'_>, path: std::path::PathBuf, format: Option<&str>) -> PyResult<()> {
        let ext = match format {
            Some(f) => f.trim_start_matches('.').to_ascii_lowercase(),
            None => path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase(),
        };
        let scene = self.inner.clone();
        pool::detached(py, move || -> Result<(), String> {
            if ext == "png" {
                let img = model::render_scene(&scene)?;
                return write_atomic(&path, |w| img.write_png(w))
                    .map_err(|e| format!("cannot write {}: {e}", path.display()));
            }
            let fmt = Format::from_extension(&ext).ok_or_else(|| {
                format!("unknown format `{ext}` (use a mesh extension such as obj, ply, stl, glb or png)")
            })?;
            let meshes = model::patch_meshes(&scene)?;
            let refs: Vec<&CoreMesh> = meshes.iter().collect();
            write_meshes(&path, fmt, &refs).map_err(|e| format!("cannot write {}: {e}", path.display()))
        })
        .map_err(PyValueError::new_err)
    }

    fn __repr__(&self) -> String {
        format!("<pdeshape.Scene {} ({} patches)>", self.inner.file, self.inner.patches.len())
    }
}

/// The folder `[import.*]` paths are read from, made absolute, so that a pickled scene
/// imports the same files in a worker whose current directory differs.
fn import_folder(folder: &std::path::Path) -> PyResult<ImportRoot> {
    std::path::absolute(folder)
        .map(ImportRoot::Dir)
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", folder.display())))
}

/// What a pickled scene holds: a dict of its text, labels, load options and the folder its
/// imports are read from (the workers that unpickle it read the same paths).
fn scene_state<'py>(py: Python<'py>, s: &IoScene, time_limit: f64) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("text", &s.source)?;
    d.set_item("file", &s.file)?;
    d.set_item("name", &s.name)?;
    let params = PyDict::new(py);
    for (k, v) in &s.options.params {
        params.set_item(k, *v)?;
    }
    d.set_item("params", params)?;
    d.set_item("solver", s.options.solver.clone())?;
    d.set_item("terms", s.options.terms)?;
    let limits = PyDict::new(py);
    for cap in Cap::ALL {
        limits.set_item(cap.name(), s.options.limits.get(cap))?;
    }
    d.set_item("limits", limits)?;
    d.set_item("time_limit", time_limit)?;
    if let ImportRoot::Dir(folder) = &s.options.imports {
        d.set_item("imports", folder)?;
    }
    Ok(d)
}

/// Unpickles a scene: [`scene_state`]'s dict solved again.
#[pyfunction]
fn _scene_from_state(py: Python<'_>, state: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
        state.get_item(k)?.ok_or_else(|| PyValueError::new_err(format!("a pickled scene without `{k}`")))
    };
    let text: String = get("text")?.extract()?;
    let file: String = get("file")?.extract()?;
    let name: String = get("name")?.extract()?;
    let limits = get("limits")?;
    let params = get("params")?;
    let opts = Scene::options(
        get("solver")?.extract()?,
        get("terms")?.extract()?,
        Some(limits.cast::<PyDict>()?),
        Some(params.cast::<PyDict>()?),
    )?;
    let time_limit = self::time_limit(get("time_limit")?.extract()?)?;
    let mut opts = opts;
    if let Some(folder) = state.get_item("imports")? {
        opts.imports = ImportRoot::Dir(folder.extract()?);
    }
    Scene::build(&text, &file, &name, opts, time_limit, py)
}

/// A picture as PNG bytes.
fn png_bytes<'py>(py: Python<'py>, img: &pdeshape_io::render::Image) -> PyResult<Bound<'py, PyBytes>> {
    let mut buf = Vec::new();
    img.write_png(&mut buf).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    Ok(PyBytes::new(py, &buf))
}

/// One solved patch of a scene.
#[pyclass(frozen, module = "pdeshape")]
struct Patch {
    scene: Arc<IoScene>,
    index: usize,
    /// The scene's time limit for meshes (seconds, 0: none).
    time_limit: f64,
}

impl Patch {
    fn get(&self) -> &ScenePatch {
        &self.scene.patches[self.index]
    }

    /// A zeroed buffer of `n` f64 for an output array: held to the scene's `memory` cap,
    /// then allocated fallibly, so a request too large for the cap or the machine raises
    /// `MemoryError` instead of aborting the interpreter.
    fn buffer(&self, n: u128, what: &str) -> PyResult<Vec<f64>> {
        let bytes = n.saturating_mul(8);
        self.scene
            .options
            .limits
            .check_bytes(bytes, what)
            .map_err(|e| PyMemoryError::new_err(py_message(&e.to_string())))?;
        let n = usize::try_from(n).map_err(|_| PyMemoryError::new_err(format!("{what}: {n} values")))?;
        let mut v = Vec::new();
        v.try_reserve_exact(n)
            .map_err(|_| PyMemoryError::new_err(format!("{what}: cannot allocate {:.3e} bytes", bytes as f64)))?;
        v.resize(n, 0.0);
        Ok(v)
    }

    /// The surface at time `t` (dynamic blends; an error for `t` on other kinds).
    fn surface(&self, t: Option<f64>) -> PyResult<Arc<dyn Surface>> {
        let p = self.get();
        match (&p.dynamic, t) {
            (Some(d), Some(t)) => {
                if !t.is_finite() {
                    return Err(PyValueError::new_err(format!("t = {t} is not finite")));
                }
                let f = d
                    .blend
                    .frame(t)
                    .map_err(|e| PyRuntimeError::new_err(format!("patch `{}` at t = {t}: {e}", p.name)))?;
                Ok(Arc::new(f))
            }
            (None, Some(_)) => {
                Err(PyValueError::new_err(format!("patch `{}` is a {} patch: it takes no t", p.name, p.kind.name())))
            }
            _ => Ok(p.surface.clone()),
        }
    }

    /// Checks the parameter array's shape and range as `pdeshape sample` does.
    fn check_params(&self, a: &ArrayView2<'_, f64>) -> PyResult<()> {
        let p = self.get();
        let cols = if p.solid.is_some() { 3 } else { 2 };
        if a.ncols() != cols {
            let what = if cols == 3 { "(N, 3) of (u, v, w)" } else { "(N, 2) of (u, v)" };
            return Err(PyValueError::new_err(format!(
                "patch `{}`: expected an array of shape {what}, got {:?}",
                p.name,
                a.shape()
            )));
        }
        let dom = p.surface.v_domain();
        for (i, row) in a.outer_iter().enumerate() {
            for (k, &x) in row.iter().enumerate() {
                let name = ["u", "v", "w"][k];
                if !x.is_finite() {
                    return Err(PyValueError::new_err(format!("row {i}: {name} = {x} is not finite")));
                }
                let in_range = if k == 1 && p.solid.is_none() {
                    dom.periodic || (dom.start..=dom.end).contains(&x)
                } else {
                    (0.0..=1.0).contains(&x)
                };
                if !in_range {
                    let range = if k == 1 && p.solid.is_none() {
                        format!("[{}, {}]", dom.start, dom.end)
                    } else {
                        "[0, 1]".into()
                    };
                    return Err(PyValueError::new_err(format!("row {i}: {name} = {x} is outside {range}")));
                }
            }
        }
        Ok(())
    }
}

#[pymethods]
impl Patch {
    /// The patch's name.
    #[getter]
    fn name(&self) -> &str {
        &self.get().name
    }

    /// Its kind: "hermite", "pde", "blend", "dynamic" or "solid".
    #[getter]
    fn kind(&self) -> &'static str {
        self.get().kind.name()
    }

    /// The mesh resolution (nu, nv) in vertices.
    #[getter]
    fn resolution(&self) -> (usize, usize) {
        self.get().resolution
    }

    /// The v domain `(start, end, periodic)`.
    #[getter]
    fn v_domain(&self) -> (f64, f64, bool) {
        let d = self.get().surface.v_domain();
        (d.start, d.end, d.periodic)
    }

    /// The time range `(t0, t1)` of a dynamic blend, else None.
    #[getter]
    fn times(&self) -> Option<(f64, f64)> {
        self.get().dynamic.as_ref().map(|d| d.times)
    }

    /// Exact points: `uv` is a float64 array (N, 2) of (u, v) — (N, 3) of (u, v, w) for a
    /// solid — and the result a float64 array (N, 3). `t` selects a dynamic blend's frame.
    /// Equal bit for bit to `pdeshape sample`.
    #[pyo3(signature = (uv, t=None))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        uv: PyReadonlyArray2<'py, f64>,
        t: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = uv.as_array();
        self.check_params(&a)?;
        let frame = match self.get().solid {
            Some(_) => None,
            None => Some(self.surface(t)?),
        };
        let target = match &frame {
            Some(s) => Target::Surface(s.as_ref()),
            None => Target::of(self.get()),
        };
        let n = a.nrows();
        let mut out = self.buffer(3 * n as u128, "the array of points")?;
        let params: Cow<'_, [f64]> = match a.as_slice() {
            Some(s) => Cow::Borrowed(s),
            None => {
                let mut c = self.buffer(a.len() as u128, "a contiguous copy of the parameters")?;
                c.iter_mut().zip(a.iter()).for_each(|(d, s)| *d = *s);
                Cow::Owned(c)
            }
        };
        let out = pool::detached(py, || {
            points_into(target, &params, &mut out);
            out
        });
        Ok(Array2::from_shape_vec((n, 3), out).expect("3 per point").into_pyarray(py))
    }

    /// Exact partial derivatives: an array (N, du + 1, dv + 1, 3) whose `[k, i, j]` is
    /// `∂^{i+j} X / ∂uⁱ ∂vʲ` at `uv[k]` (`du ≤ 2`, `dv ≤ 4`; surfaces only).
    #[pyo3(signature = (uv, du=1, dv=1, t=None))]
    fn derivatives<'py>(
        &self,
        py: Python<'py>,
        uv: PyReadonlyArray2<'py, f64>,
        du: usize,
        dv: usize,
        t: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray4<f64>>> {
        if self.get().solid.is_some() {
            return Err(PyValueError::new_err(
                "derivatives are for surface patches; a solid takes evaluate((u, v, w))",
            ));
        }
        if du > 2 || dv > 4 {
            return Err(PyValueError::new_err(format!(
                "derivative orders du = {du}, dv = {dv}: at most du = 2, dv = 4"
            )));
        }
        let a = uv.as_array();
        self.check_params(&a)?;
        let s = self.surface(t)?;
        let n = a.nrows();
        let per = (du + 1) * (dv + 1) * 3;
        let mut out = self.buffer(n as u128 * per as u128, "the array of derivatives")?;
        let out = pool::detached(py, || {
            for (dst, row) in out.chunks_mut(per).zip(a.outer_iter()) {
                for (k, d) in s.derivatives(row[0], row[1], du, dv).iter().enumerate() {
                    dst[3 * k..3 * k + 3].copy_from_slice(&[d.x, d.y, d.z]);
                }
            }
            out
        });
        Ok(Array4::from_shape_vec((n, du + 1, dv + 1, 3), out).expect("sizes agree").into_pyarray(py))
    }

    /// The patch's mesh, as the exporters write it: `resolution=(nu, nv)` overrides the
    /// scene's (surface patches without a trim), `t` selects a dynamic frame.
    #[pyo3(signature = (resolution=None, t=None))]
    fn mesh(&self, py: Python<'_>, resolution: Option<(usize, usize)>, t: Option<f64>) -> PyResult<Mesh> {
        let mut p = self.get().clone();
        if let Some(t) = t {
            if p.dynamic.is_none() {
                return Err(PyValueError::new_err(format!(
                    "patch `{}` is a {} patch: it takes no t",
                    p.name,
                    p.kind.name()
                )));
            }
            // the frame is solved (and kept) here, so a time the blend refuses raises as
            // it does in `evaluate` (t = 1e308 was meshed)
            self.surface(Some(t))?;
        }
        if let Some((nu, nv)) = resolution {
            if p.trim.is_some() || p.solid.is_some() {
                return Err(PyValueError::new_err(format!(
                    "patch `{}`: resolution applies to untrimmed surface patches (this one meshes its own region)",
                    p.name
                )));
            }
            if nu < 2 || nv < 2 {
                return Err(PyValueError::new_err(format!("resolution ({nu}, {nv}): at least 2 × 2")));
            }
            self.scene
                .options
                .limits
                .check(Cap::Vertices, (nu as u128) * (nv as u128), "the mesh's vertices")
                .map_err(|e| PyValueError::new_err(py_message(&e.to_string())))?;
            p.resolution = (nu, nv);
        }
        let m = limited(py, self.time_limit, "the mesh", || model::patch_mesh_at(&p, t))?
            .map_err(PyRuntimeError::new_err)?;
        Ok(Mesh::from_core(py, &m))
    }

    /// Pickling: the scene's state and the patch's index (unpickling solves the scene
    /// again, as a pickled `Scene` does).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let restore = py.import("pdeshape._native")?.getattr("_patch_from_state")?;
        let state = scene_state(py, &self.scene, self.time_limit)?;
        Ok((restore, (state, self.index).into_pyobject(py)?))
    }

    /// An interactive 3D view in Jupyter (a pythreejs widget; `pip install pythreejs`):
    /// see `pdeshape.notebook.show`.
    #[pyo3(signature = (*, resolution=None, width=800, height=600))]
    fn show<'py>(
        slf: &Bound<'py, Self>,
        resolution: Option<(usize, usize)>,
        width: i64,
        height: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        notebook_show(slf.as_any(), resolution, width, height)
    }

    /// The patch drawn alone in the scene's view (PNG bytes): Jupyter shows it.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let p = self.get().clone();
        let r = self.scene.render.clone();
        let img = limited(py, self.time_limit, "the picture", move || {
            model::patch_mesh(&p).map(|m| model::render_meshes(&[m], &[], &[p.color], &r))
        })?
        .map_err(PyRuntimeError::new_err)?;
        png_bytes(py, &img)
    }

    fn __repr__(&self) -> String {
        let p = self.get();
        format!("<pdeshape.Patch {} ({})>", p.name, p.kind.name())
    }
}

/// Unpickles a patch: its scene solved again, the patch at `index`.
#[pyfunction]
fn _patch_from_state(py: Python<'_>, state: &Bound<'_, PyDict>, index: usize) -> PyResult<Patch> {
    let scene = _scene_from_state(py, state)?;
    if index >= scene.inner.patches.len() {
        return Err(PyValueError::new_err(format!(
            "a pickled patch {index} of a scene of {} patches",
            scene.inner.patches.len()
        )));
    }
    Ok(Patch { scene: scene.inner, index, time_limit: scene.time_limit })
}

/// A triangle mesh as numpy arrays, ready for trimesh, pyvista, libigl or matplotlib:
/// `vertices` (N, 3) float64, `faces` (M, 3) uint32 (counter-clockwise about the normal;
/// quadrilaterals split along their first diagonal), `normals` (N, 3) float64 (unit, exact),
/// `uvs` (N, 2) float64 (the patch parameters scaled to [0, 1]) and `fields` (name → (N,)
/// float64 per-vertex values).
#[pyclass(frozen, module = "pdeshape")]
struct Mesh {
    /// The patch's (or the given) name.
    #[pyo3(get)]
    name: String,
    /// (N, 3) float64 vertex positions.
    #[pyo3(get)]
    vertices: Py<PyArray2<f64>>,
    /// (M, 3) uint32 vertex indices, counter-clockwise about the normal.
    #[pyo3(get)]
    faces: Py<PyArray2<u32>>,
    /// (N, 3) float64 unit normals (exact, from the surface's derivatives), or None.
    #[pyo3(get)]
    normals: Option<Py<PyArray2<f64>>>,
    /// (N, 2) float64 patch parameters scaled to [0, 1], or None.
    #[pyo3(get)]
    uvs: Option<Py<PyArray2<f64>>>,
    /// Per-vertex values: name → (N,) float64.
    #[pyo3(get)]
    fields: Py<PyDict>,
}

fn vec3s(py: Python<'_>, v: &[Vec3]) -> Py<PyArray2<f64>> {
    let flat: Vec<f64> = v.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    Array2::from_shape_vec((v.len(), 3), flat).expect("3 per vertex").into_pyarray(py).unbind()
}

impl Mesh {
    fn from_core(py: Python<'_>, m: &CoreMesh) -> Mesh {
        let mut faces: Vec<u32> = m.triangles.iter().flatten().copied().collect();
        for q in &m.quads {
            faces.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
        }
        let nf = faces.len() / 3;
        let uvs = (!m.uvs.is_empty()).then(|| {
            let flat: Vec<f64> = m.uvs.iter().flatten().copied().collect();
            Array2::from_shape_vec((m.uvs.len(), 2), flat).expect("2 per vertex").into_pyarray(py).unbind()
        });
        let fields = PyDict::new(py);
        for f in &m.fields {
            let a: Bound<'_, PyArray1<f64>> = Array1::from_vec(f.values.clone()).into_pyarray(py);
            fields.set_item(&f.name, a).expect("a dict takes str keys");
        }
        Mesh {
            name: m.name.clone(),
            vertices: vec3s(py, &m.positions),
            faces: Array2::from_shape_vec((nf, 3), faces).expect("3 per face").into_pyarray(py).unbind(),
            normals: (!m.normals.is_empty()).then(|| vec3s(py, &m.normals)),
            uvs,
            fields: fields.unbind(),
        }
    }
}

#[pymethods]
impl Mesh {
    /// A mesh from arrays: `vertices` (N, 3) floats, `faces` (M, 3) indices into them,
    /// and optionally `normals` (N, 3), `uvs` (N, 2) and `fields` (name → (N,)). The arrays
    /// are copied into float64 and uint32 arrays; errors name the array and the index.
    #[new]
    #[pyo3(signature = (vertices, faces, normals=None, uvs=None, fields=None, name="mesh"))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        normals: Option<&Bound<'_, PyAny>>,
        uvs: Option<&Bound<'_, PyAny>>,
        fields: Option<&Bound<'_, PyDict>>,
        name: &str,
    ) -> PyResult<Mesh> {
        let np = py.import("numpy")?;
        let floats = |a: &Bound<'_, PyAny>, what: &str, cols: usize| -> PyResult<Py<PyArray2<f64>>> {
            let a = np.call_method1("array", (a, "float64"))?;
            let arr: Bound<'_, PyArray2<f64>> =
                a.cast_into().map_err(|_| PyValueError::new_err(format!("{what}: an array of shape (N, {cols})")))?;
            let view = arr.readonly();
            let v = view.as_array();
            if v.ncols() != cols {
                return Err(PyValueError::new_err(format!("{what}: shape {:?}, not (N, {cols})", v.shape())));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "{what}[{}, {}] = {} is not finite",
                    i / cols,
                    i % cols,
                    v.iter().nth(i).copied().unwrap_or(f64::NAN)
                )));
            }
            drop(view);
            Ok(arr.unbind())
        };
        let vertices = floats(vertices, "vertices", 3)?;
        let n = vertices.bind(py).shape()[0];
        let f = np.call_method1("array", (faces, "int64"))?;
        let f: Bound<'_, PyArray2<i64>> =
            f.cast_into().map_err(|_| PyValueError::new_err("faces: an integer array of shape (M, 3)"))?;
        let fv = f.readonly();
        let fa = fv.as_array();
        if fa.ncols() != 3 {
            return Err(PyValueError::new_err(format!("faces: shape {:?}, not (M, 3)", fa.shape())));
        }
        let mut tris = Vec::with_capacity(fa.len());
        for (i, r) in fa.rows().into_iter().enumerate() {
            for k in 0..3 {
                if r[k] < 0 || r[k] as u128 >= n as u128 {
                    return Err(PyValueError::new_err(format!(
                        "faces[{i}, {k}] = {}: out of range for {n} vertices",
                        r[k]
                    )));
                }
                tris.push(r[k] as u32);
            }
        }
        let nf = fa.nrows();
        let per_vertex = |a: Py<PyArray2<f64>>, what: &str| -> PyResult<Py<PyArray2<f64>>> {
            let rows = a.bind(py).shape()[0];
            if rows != n {
                return Err(PyValueError::new_err(format!("{what}: {rows} rows for {n} vertices")));
            }
            Ok(a)
        };
        let normals = normals.map(|a| floats(a, "normals", 3).and_then(|a| per_vertex(a, "normals"))).transpose()?;
        let uvs = uvs.map(|a| floats(a, "uvs", 2).and_then(|a| per_vertex(a, "uvs"))).transpose()?;
        let out_fields = PyDict::new(py);
        if let Some(fields) = fields {
            for (k, v) in fields.iter() {
                let key: String = k.extract().map_err(|_| PyTypeError::new_err("fields: the keys are names (str)"))?;
                let a = np.call_method1("array", (v, "float64"))?;
                let a: Bound<'_, PyArray1<f64>> = a
                    .cast_into()
                    .map_err(|_| PyValueError::new_err(format!("fields['{key}']: an array of shape (N,)")))?;
                if a.len() != n {
                    return Err(PyValueError::new_err(format!("fields['{key}']: {} values for {n} vertices", a.len())));
                }
                out_fields.set_item(key, a)?;
            }
        }
        Ok(Mesh {
            name: name.to_string(),
            vertices,
            faces: Array2::from_shape_vec((nf, 3), tris).expect("3 per face").into_pyarray(py).unbind(),
            normals,
            uvs,
            fields: out_fields.unbind(),
        })
    }

    /// Pickling: the arrays (numpy pickles them).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let cls = py.import("pdeshape._native")?.getattr("Mesh")?;
        let args = (
            self.vertices.clone_ref(py),
            self.faces.clone_ref(py),
            self.normals.as_ref().map(|a| a.clone_ref(py)),
            self.uvs.as_ref().map(|a| a.clone_ref(py)),
            self.fields.clone_ref(py),
            self.name.clone(),
        );
        Ok((cls, args.into_pyobject(py)?))
    }

    /// An interactive 3D view in Jupyter (a pythreejs widget; `pip install pythreejs`):
    /// see `pdeshape.notebook.show`.
    #[pyo3(signature = (*, resolution=None, width=800, height=600))]
    fn show<'py>(
        slf: &Bound<'py, Self>,
        resolution: Option<(usize, usize)>,
        width: i64,
        height: i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        notebook_show(slf.as_any(), resolution, width, height)
    }

    /// The mesh drawn shaded (PNG bytes), in the view `render` gives mesh files: Jupyter
    /// shows it.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let v = self.vertices.bind(py).readonly();
        let positions: Vec<Vec3> = v.as_array().rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect();
        let f = self.faces.bind(py).readonly();
        let triangles: Vec<[u32; 3]> = f.as_array().rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
        drop((v, f));
        let img = pool::detached(py, move || {
            let m = pdeshape_core::trimesh::TriMesh { positions, triangles };
            pdeshape_io::mesh_holes::render_trimesh(&m, &pdeshape_io::scene::RenderSettings::default())
        })
        .map_err(PyRuntimeError::new_err)?;
        png_bytes(py, &img)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<pdeshape.Mesh {}: {} vertices, {} triangles>",
            self.name,
            self.vertices.bind(py).shape()[0],
            self.faces.bind(py).shape()[0]
        )
    }
}

pyo3::create_exception!(
    pdeshape,
    ModelError,
    PyException,
    "A model file (STEP) that cannot be read or whose holes cannot be filled: `str(e)` is \
     the CLI's message, naming the file, line and entity."
);

/// The caps of a `limits={...}` dict.
fn limits_of(limits: Option<&Bound<'_, PyDict>>) -> PyResult<Limits> {
    Ok(Scene::options(None, None, limits, None)?.limits)
}

/// A JSON value as the Python object `json.loads` makes of it.
fn to_python(py: Python<'_>, v: &serde_json::Value) -> PyResult<Py<PyAny>> {
    Ok(py.import("json")?.call_method1("loads", (v.to_string(),))?.unbind())
}

fn model_error(e: impl std::fmt::Display) -> PyErr {
    ModelError::new_err(py_message(&e.to_string()))
}

/// The holes of a model: the dict `pdeshape holes MODEL --json` prints. For a STEP model
/// the loops of its free boundary, each with its edges, the faces around, length,
/// bounding box and the angle between the faces at each corner; for a triangle mesh
/// (.obj, .ply, .stl) its boundary loops with their edge counts, lengths and boxes.
///
/// `replace_faces` (STEP models): faces taken out first, by their `#id`s; the loops they
/// leave are listed as holes.
///
/// >>> pdeshape.holes("part.step")["holes"][0]["edges"]
/// [21]
#[pyfunction]
#[pyo3(signature = (path, *, replace_faces=None, limits=None))]
fn holes(
    py: Python<'_>,
    path: std::path::PathBuf,
    replace_faces: Option<Vec<u64>>,
    limits: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<PyAny>> {
    let limits = limits_of(limits)?;
    let replace = replace_faces.unwrap_or_default();
    no_faces_in_a_mesh(&path, &replace)?;
    let report = pool::detached(py, || -> Result<serde_json::Value, String> {
        if pdeshape_io::import::mesh::MeshFormat::from_path(&path).is_some() {
            let mf = pdeshape_io::import::mesh::read_mesh(&path, &limits).map_err(|e| e.to_string())?;
            let loops = pdeshape_core::trimesh::boundary(&mf.mesh).map_err(|e| format!("{}: {e}", mf.file))?;
            return serde_json::to_value(pdeshape_io::mesh_holes::mesh_holes_report(&mf, &loops))
                .map_err(|e| e.to_string());
        }
        let m = pdeshape_io::import::step::read_step_without(&path, &replace, &limits).map_err(|e| e.to_string())?;
        let hs = pdeshape_core::brep::holes(&m.brep);
        serde_json::to_value(pdeshape_io::holes::holes_report(&m, &hs)).map_err(|e| e.to_string())
    });
    to_python(py, &report.map_err(model_error)?)
}

/// `replace_faces` names faces of a STEP model: a mesh has none.
fn no_faces_in_a_mesh(path: &std::path::Path, replace: &[u64]) -> PyResult<()> {
    if !replace.is_empty() && pdeshape_io::import::mesh::MeshFormat::from_path(path).is_some() {
        return Err(PyValueError::new_err(format!(
            "{}: replace_faces takes faces of a STEP model; a triangle mesh has none",
            path.display()
        )));
    }
    Ok(())
}

/// Fills holes with fills of order 4 (G1) or 6 (G2), as `pdeshape fill-holes` does.
///
/// - `fill_holes(path, out)`: a STEP model is written to `out` with the new faces sewn
///   in; a triangle mesh (.obj, .ply, .stl) with the new triangles stitched to each hole's
///   own vertices. Returns one dict of figures per filled hole.
/// - `fill_holes(vertices, faces)`: a mesh as numpy arrays — float (N, 3) and integer
///   (M, 3), counter-clockwise about the outside, as trimesh, pyvista and libigl hold
///   them — returns `(vertices, faces, figures)`: the input rows first and unchanged, the
///   fills' rows after them.
///
/// `holes` picks holes by their numbers in `pdeshape.holes` (from 1); `max_edges` leaves
/// bigger loops open; `replace_faces` (STEP models) takes faces out first, by their
/// `#id`s, so that fills replace them. Raises `ModelError` when the model cannot be read or an asked hole
/// cannot be filled (nothing is written), `ValueError` for arrays of the wrong shape or
/// indices out of range, `TimeoutError` past `time_limit` seconds.
#[pyfunction]
#[pyo3(signature = (model, out, *, order=4, holes=None, max_edges=None, relative_tolerance=1e-7, replace_faces=None, limits=None, time_limit=None))]
#[allow(clippy::too_many_arguments)]
fn fill_holes(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    out: &Bound<'_, PyAny>,
    order: usize,
    holes: Option<Vec<usize>>,
    max_edges: Option<usize>,
    relative_tolerance: f64,
    replace_faces: Option<Vec<u64>>,
    limits: Option<&Bound<'_, PyDict>>,
    time_limit: Option<f64>,
) -> PyResult<Py<PyAny>> {
    if order != 4 && order != 6 {
        return Err(PyValueError::new_err(format!("order = {order}: 4 (G1) or 6 (G2)")));
    }
    let limits = limits_of(limits)?;
    let seconds = self::time_limit(time_limit)?;
    if !(relative_tolerance.is_finite() && relative_tolerance > 0.0) {
        return Err(PyValueError::new_err(format!("relative_tolerance = {relative_tolerance}: a positive number")));
    }
    if holes.is_some() && max_edges.is_some() {
        return Err(PyValueError::new_err("holes and max_edges do not go together: holes picks the holes itself"));
    }
    let o = pdeshape_io::holes::FillHolesOptions { order, holes, max_edges, relative: relative_tolerance };
    let replace = replace_faces.unwrap_or_default();
    let Ok(path) = model.extract::<std::path::PathBuf>() else {
        if !replace.is_empty() {
            return Err(PyValueError::new_err("replace_faces takes faces of a STEP model; a mesh has none"));
        }
        return fill_mesh_arrays(py, model, out, &o, &limits, seconds);
    };
    no_faces_in_a_mesh(&path, &replace)?;
    let out: std::path::PathBuf = out.extract()?;
    let done = limited(py, seconds, "filling the holes", || -> Result<serde_json::Value, String> {
        if pdeshape_io::import::mesh::MeshFormat::from_path(&path).is_some() {
            let mf = pdeshape_io::import::mesh::read_mesh(&path, &limits).map_err(|e| e.to_string())?;
            let loops = pdeshape_core::trimesh::boundary(&mf.mesh).map_err(|e| format!("{}: {e}", mf.file))?;
            let (filled, reports) = pdeshape_io::mesh_holes::fill_mesh_holes(&mf, &loops, &o, &limits)
                .map_err(|e| format!("{}: {e}", mf.file))?;
            if reports.is_empty() {
                return Err(format!("{}: no hole to fill", mf.file));
            }
            pdeshape_io::mesh_holes::write_trimesh(&out, &filled)?;
            return serde_json::to_value(&reports).map_err(|e| e.to_string());
        }
        let m = pdeshape_io::import::step::read_step_without(&path, &replace, &limits).map_err(|e| e.to_string())?;
        let hs = pdeshape_core::brep::holes(&m.brep);
        let filled = pdeshape_io::holes::fill_holes(&m, &hs, &o).map_err(|e| format!("{}: {e}", m.file))?;
        if filled.is_empty() {
            return Err(format!("{}: no hole to fill", m.file));
        }
        pdeshape_io::holes::write_filled(&m, &hs, &filled, &out)?;
        Ok(serde_json::Value::Array(
            filled
                .iter()
                .map(|f| {
                    serde_json::json!({
                        "index": f.index,
                        "order": order,
                        "control_points": [f.fit.points.0, f.fit.points.1],
                        "measured_deviation": f.fit.max_deviation,
                        "seam": f.seam,
                    })
                })
                .collect(),
        ))
    })?;
    to_python(py, &done.map_err(model_error)?)
}

/// `fill_holes(vertices, faces)`: the arrays checked, the mesh filled, new arrays back.
fn fill_mesh_arrays(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    o: &pdeshape_io::holes::FillHolesOptions,
    limits: &Limits,
    seconds: f64,
) -> PyResult<Py<PyAny>> {
    let np = py.import("numpy")?;
    let v = np.call_method1("ascontiguousarray", (vertices, "float64"))?;
    let f = np.call_method1("ascontiguousarray", (faces, "int64"))?;
    let v: PyReadonlyArray2<'_, f64> =
        v.extract().map_err(|_| PyValueError::new_err("vertices: a float array of shape (N, 3)"))?;
    let f: PyReadonlyArray2<'_, i64> =
        f.extract().map_err(|_| PyValueError::new_err("faces: an integer array of shape (M, 3)"))?;
    let (va, fa) = (v.as_array(), f.as_array());
    if va.ncols() != 3 {
        return Err(PyValueError::new_err(format!("vertices: shape ({}, {}), not (N, 3)", va.nrows(), va.ncols())));
    }
    if fa.ncols() != 3 {
        return Err(PyValueError::new_err(format!("faces: shape ({}, {}), not (M, 3)", fa.nrows(), fa.ncols())));
    }
    limits
        .check(Cap::Entities, (va.nrows() + fa.nrows()) as u128, "the mesh's vertices and faces")
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let positions: Vec<Vec3> = va.rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect();
    let mut triangles = Vec::with_capacity(fa.nrows());
    for (i, r) in fa.rows().into_iter().enumerate() {
        let mut t = [0u32; 3];
        for k in 0..3 {
            if r[k] < 0 || r[k] as usize >= positions.len() {
                return Err(PyValueError::new_err(format!(
                    "faces[{i}, {k}] = {}: out of range for {} vertices",
                    r[k],
                    positions.len()
                )));
            }
            t[k] = r[k] as u32;
        }
        triangles.push(t);
    }
    let mf = pdeshape_io::import::mesh::MeshFile {
        file: "the mesh".into(),
        format: pdeshape_io::import::mesh::MeshFormat::Obj,
        binary: false,
        mesh: pdeshape_core::trimesh::TriMesh { positions, triangles },
        polygons_split: 0,
    };
    let done = limited(py, seconds, "filling the holes", || {
        let loops = pdeshape_core::trimesh::boundary(&mf.mesh).map_err(|e| e.to_string())?;
        pdeshape_io::mesh_holes::fill_mesh_holes(&mf, &loops, o, limits)
    })?;
    let (m, reports) = done.map_err(model_error)?;
    let verts = vec3s(py, &m.positions);
    let tris: Vec<u32> = m.triangles.iter().flatten().copied().collect();
    let tris = Array2::from_shape_vec((m.triangles.len(), 3), tris)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?
        .into_pyarray(py);
    let figs = to_python(py, &serde_json::to_value(&reports).map_err(|e| PyRuntimeError::new_err(e.to_string()))?)?;
    Ok((verts, tris, figs).into_pyobject(py)?.into_any().unbind())
}

/// PDE-based shape design: exact PDE surfaces, blends and solids (Bloor–Wilson's PDE
/// method and its successors) from Python.
///
/// Load a scene file (the same TOML the `pdeshape` CLI reads), change its parameters, and
/// evaluate its solved patches exactly at numpy arrays of parameters, or mesh them:
///
///     import numpy as np, pdeshape
///     scene = pdeshape.Scene.load("examples/klein-bottle.toml").set(a=1.37)
///     klein = scene.patches[0]
///     points = klein.evaluate(np.array([[0.5, 0.0], [0.25, 1.0]]))   # (2, 3) float64
///     mesh = klein.mesh()           # mesh.vertices, mesh.faces, mesh.normals, mesh.uvs
///     report = scene.check()        # the dict `pdeshape check --json` prints
///
/// Errors in scene files raise `pdeshape.SceneError` with the file, line and column.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Patch>()?;
    m.add_class::<Mesh>()?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("ModelError", m.py().get_type::<ModelError>())?;
    m.add_function(wrap_pyfunction!(holes, m)?)?;
    m.add_function(wrap_pyfunction!(fill_holes, m)?)?;
    m.add_function(wrap_pyfunction!(_scene_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(_patch_from_state, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
