//! Python values as scene text: the tables a `Scene(...)` is built from (dicts, lists,
//! tuples, numpy arrays and scalars, numbers, strings) written as the TOML a scene file
//! holds, in the scene file's own vocabulary. The scene is then parsed from that text, so
//! a scene built from Python and the same scene written by hand are one thing, and
//! `to_toml` returns exactly what was solved.
//!
//! Floats are written in Rust's shortest round-trip form, so every number reads back to
//! the same bits. Values TOML cannot hold (NaN, ±∞, `None`, other objects) are errors that
//! name the argument and the index (`curves.c.bspline[3][1] = nan is not finite`).
//!
//! The text is held to the `scene` cap while it is written: each value is charged at least
//! the bytes it takes in the text (two for a number and its separator, a string's length),
//! and a numpy array is refused by its size before it becomes a Python list, so an array
//! of 10⁹ values is refused at once, not after gigabytes of lists and text.

use pdeshape_core::limits::{Cap, Limits};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml_edit::{Array, DocumentMut, InlineTable, Item, Table, Value};

/// The scene tables whose entries are tables themselves (`[patches.NAME]`).
const TABLES_OF_TABLES: [&str; 3] = ["curves", "surfaces", "patches"];

/// The bytes of text still allowed, and how a value over them is reported.
pub struct Budget<'a> {
    left: u128,
    limits: &'a Limits,
}

impl<'a> Budget<'a> {
    /// The `scene` cap of `limits`, in bytes.
    pub fn new(limits: &'a Limits) -> Self {
        Budget { left: (limits.get(Cap::Scene) as u128) << 20, limits }
    }

    /// Takes `bytes` (a lower bound of what the value at `path` adds to the text).
    fn take(&mut self, bytes: u128, path: &str) -> PyResult<()> {
        if bytes <= self.left {
            self.left -= bytes;
            return Ok(());
        }
        let cap = self.limits.get(Cap::Scene) as u128;
        let used = (cap << 20) - self.left + bytes;
        let e = self.limits.check(
            Cap::Scene,
            used.div_ceil(1 << 20),
            &format!("the scene text's size (counted up to {path})"),
        );
        Err(crate::SceneError::new_err(crate::py_message(&e.map_or_else(|e| e.to_string(), |_| String::new()))))
    }
}

/// Writes `tables` (top-level key → value, in the order given) as scene text, within
/// `budget`.
pub fn scene_text(tables: &Bound<'_, PyDict>, budget: &mut Budget<'_>) -> PyResult<String> {
    let mut doc = DocumentMut::new();
    for (k, v) in tables.iter() {
        let key: String = k.extract().map_err(|_| PyTypeError::new_err("scene tables are named by strings"))?;
        let item = if let Ok(d) = v.cast::<PyDict>() {
            let nested = TABLES_OF_TABLES.contains(&key.as_str());
            Item::Table(table(d, &key, nested, budget)?)
        } else {
            Item::Value(value(&v, &key, budget)?)
        };
        doc.insert(&key, item);
    }
    Ok(doc.to_string())
}

/// A dict as a `[table]`; `nested`: its dict entries as `[table.entry]` tables too.
fn table(d: &Bound<'_, PyDict>, path: &str, nested: bool, budget: &mut Budget<'_>) -> PyResult<Table> {
    let mut t = Table::new();
    for (k, v) in d.iter() {
        let key = key(&k, path)?;
        let here = format!("{path}.{key}");
        budget.take(key.len() as u128 + 4, &here)?;
        let item = match v.cast::<PyDict>() {
            Ok(inner) if nested => Item::Table(table(inner, &here, false, budget)?),
            _ => Item::Value(value(&v, &here, budget)?),
        };
        t.insert(&key, item);
    }
    Ok(t)
}

fn key(k: &Bound<'_, PyAny>, path: &str) -> PyResult<String> {
    k.extract().map_err(|_| PyTypeError::new_err(format!("{path}: keys are strings, not {}", type_name(k))))
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into())
}

/// One value: bool, integer, finite float, string, dict (inline table) or a sequence
/// (list, tuple, numpy array of any dimension) as an array.
fn value(v: &Bound<'_, PyAny>, path: &str, budget: &mut Budget<'_>) -> PyResult<Value> {
    // a scalar and its separator take at least two bytes
    budget.take(2, path)?;
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::from(v.is_truthy()?));
    }
    if let Ok(s) = v.cast::<PyString>() {
        let s = s.to_cow()?;
        budget.take(s.len() as u128, path)?;
        return Ok(Value::from(s.as_ref()));
    }
    if v.is_instance_of::<PyFloat>() {
        return float(v.extract()?, path);
    }
    if v.is_instance_of::<PyInt>() {
        return match v.extract::<i64>() {
            Ok(i) => Ok(Value::from(i)),
            Err(_) => Err(PyValueError::new_err(format!("{path} = {v}: an integer beyond 64 bits"))),
        };
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = InlineTable::new();
        for (k, x) in d.iter() {
            let key = key(&k, path)?;
            budget.take(key.len() as u128 + 3, path)?;
            t.insert(&key, value(&x, &format!("{path}.{key}"), budget)?);
        }
        return Ok(Value::InlineTable(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut a = Array::new();
        for (i, x) in v.try_iter()?.enumerate() {
            a.push(value(&x?, &format!("{path}[{i}]"), budget)?);
        }
        return Ok(Value::Array(a));
    }
    // numpy arrays and scalars (bool_, integer and float32 scalars, arrays of any
    // dimension): their Python values, which the cases above take
    if v.hasattr("tolist")? {
        // a numpy array's values take two bytes each at least: refused by its size before
        // `tolist` makes them Python objects
        if let Ok(size) = v.getattr("size").and_then(|n| n.extract::<u64>()) {
            budget.take(2 * size as u128, path)?;
        }
        let plain = v.call_method0("tolist")?;
        if !plain.get_type().is(v.get_type()) {
            return value(&plain, path, budget);
        }
    }
    Err(PyTypeError::new_err(format!(
        "{path}: a {} cannot go into a scene (numbers, strings, booleans, lists, tuples, dicts and numpy arrays can)",
        type_name(v)
    )))
}

fn float(x: f64, path: &str) -> PyResult<Value> {
    if !x.is_finite() {
        return Err(PyValueError::new_err(format!("{path} = {x} is not finite")));
    }
    // shortest round-trip digits either way; the exponent form for very large and very
    // small magnitudes (1e300 rather than 301 digits)
    if x != 0.0 && !(1e-5..1e16).contains(&x.abs()) {
        return format!("{x:e}").parse::<Value>().map_err(|e| PyValueError::new_err(format!("{path} = {x:e}: {e}")));
    }
    Ok(Value::from(x))
}
