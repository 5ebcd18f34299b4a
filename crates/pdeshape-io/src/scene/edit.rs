//! Edits of the scene text (the editor's sliders, handles and trim edits): set, insert or
//! delete a value at a path of
//! table keys and array indices, applied with `toml_edit` so the rest of the file (comments,
//! layout) is kept; and the editable items the page shows (curve control points, trims).

use serde::Deserialize;
use serde_json::{Value, json};
use toml_edit::{DocumentMut, Item, Value as TValue};

/// One path segment: a table key or an array index.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Seg {
    /// Table key.
    Key(String),
    /// Array index.
    Index(usize),
}

/// An edit of the scene text.
#[derive(Clone, Debug, Deserialize)]
pub struct Edit {
    /// `set` (default), `insert` (before the index) or `delete`.
    #[serde(default)]
    pub op: Option<String>,
    /// Path to the value.
    pub path: Vec<Seg>,
    /// New value (numbers or arrays of numbers) for `set` and `insert`.
    #[serde(default)]
    pub value: Value,
}

fn to_toml(v: &Value) -> Result<TValue, String> {
    match v {
        // integers stay integers (`resolution`, `modes`, `degree` take only integers)
        Value::Number(n) if n.is_i64() => Ok(TValue::from(n.as_i64().expect("checked"))),
        Value::Number(n) => {
            let x = n.as_f64().ok_or("not a number")?;
            if !x.is_finite() {
                return Err("a value is not finite".into());
            }
            Ok(TValue::from(x))
        }
        Value::Array(a) => {
            let mut arr = toml_edit::Array::new();
            for x in a {
                arr.push(to_toml(x)?);
            }
            Ok(TValue::Array(arr))
        }
        Value::String(s) => Ok(TValue::from(s.as_str())),
        _ => Err(format!("cannot put {v} into a scene file")),
    }
}

fn path_text(path: &[Seg]) -> String {
    path.iter()
        .map(|s| match s {
            Seg::Key(k) => format!(".{k}"),
            Seg::Index(i) => format!("[{i}]"),
        })
        .collect::<String>()
        .trim_start_matches('.')
        .to_string()
}

/// Applies the edits in order; errors name the path.
pub fn apply(text: &str, edits: &[Edit]) -> Result<String, String> {
    if edits.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc: DocumentMut = text.parse().map_err(|e| format!("scene text: {e}"))?;
    for e in edits {
        let where_ = path_text(&e.path);
        if e.op.as_deref() == Some("fill") {
            fill_hole(&mut doc, &e.path, &e.value).map_err(|m| format!("edit {where_}: {m}"))?;
            continue;
        }
        let (last, parents) = e.path.split_last().ok_or("an edit needs a path")?;
        let mut item: &mut Item = doc.as_item_mut();
        for seg in parents {
            let missing = || format!("edit {where_}: no such entry `{}`", path_text(std::slice::from_ref(seg)));
            let exists = match seg {
                Seg::Key(k) => item.get(k.as_str()).is_some_and(|x| !x.is_none()),
                Seg::Index(i) => item.get(*i).is_some_and(|x| !x.is_none()),
            };
            if !exists {
                return Err(missing());
            }
            item = match seg {
                Seg::Key(k) => item.get_mut(k.as_str()),
                Seg::Index(i) => item.get_mut(*i),
            }
            .ok_or_else(missing)?;
        }
        let op = e.op.as_deref().unwrap_or("set");
        match (op, last) {
            ("set", Seg::Key(k)) => {
                let v = to_toml(&e.value).map_err(|m| format!("edit {where_}: {m}"))?;
                let t = item.as_table_like_mut().ok_or_else(|| format!("edit {where_}: not inside a table"))?;
                t.insert(k, Item::Value(v));
            }
            (op, Seg::Index(i)) => {
                let arr = item.as_array_mut().ok_or_else(|| format!("edit {where_}: not inside an array"))?;
                match op {
                    "set" if *i < arr.len() => {
                        let v = to_toml(&e.value).map_err(|m| format!("edit {where_}: {m}"))?;
                        arr.replace(*i, v);
                    }
                    "insert" if *i <= arr.len() => {
                        let v = to_toml(&e.value).map_err(|m| format!("edit {where_}: {m}"))?;
                        arr.insert(*i, v);
                    }
                    "delete" if *i < arr.len() => {
                        arr.remove(*i);
                    }
                    _ => return Err(format!("edit {where_}: `{op}` at index {i} of an array of {}", arr.len())),
                }
            }
            (op, _) => return Err(format!("edit {where_}: unknown operation `{op}`")),
        }
    }
    Ok(doc.to_string())
}

/// The `fill` edit (the editor's click on a hole): `[patches.NAME]` of `kind = "fill"`,
/// `hole = VALUE`, `order = 6` added, at the path `["patches", NAME]`.
fn fill_hole(doc: &mut DocumentMut, path: &[Seg], value: &Value) -> Result<(), String> {
    let [Seg::Key(patches), Seg::Key(name)] = path else {
        return Err("a fill is added at [\"patches\", NAME]".into());
    };
    let Value::String(hole) = value else {
        return Err("a fill's value is the hole's name (\"MODEL.holeK\")".into());
    };
    if patches != "patches" {
        return Err("a fill is added at [\"patches\", NAME]".into());
    }
    let table = doc
        .as_table_mut()
        .entry("patches")
        .or_insert_with(|| {
            let mut t = toml_edit::Table::new();
            t.set_implicit(true);
            Item::Table(t)
        })
        .as_table_mut()
        .ok_or("`patches` is not a table")?;
    if table.contains_key(name) {
        return Err(format!("the patch `{name}` exists"));
    }
    let mut t = toml_edit::Table::new();
    t.insert("kind", toml_edit::value("fill"));
    t.insert("hole", toml_edit::value(hole.as_str()));
    t.insert("order", toml_edit::value(6));
    table.insert(name, Item::Table(t));
    Ok(())
}

/// The scene text with parameter values replaced (`a = 1.37` for `--set a=1.37`): the text
/// that, parsed without overrides, resolves as `text` does with them. A parameter written
/// as a table (`a = { value = 1, min = 0 }`) gets its `value` replaced, its range kept; an
/// expression parameter given a value becomes that number, as an override makes it. Names
/// go in sorted order, so the text is the same for the same overrides.
pub fn with_parameters(text: &str, values: &std::collections::HashMap<String, f64>) -> Result<String, String> {
    if values.is_empty() {
        return Ok(text.to_string());
    }
    let doc: DocumentMut = text.parse().map_err(|e| format!("scene text: {e}"))?;
    let params = doc.get("parameters").and_then(|p| p.as_table_like());
    let mut names: Vec<&String> = values.keys().collect();
    names.sort();
    let mut edits = Vec::with_capacity(names.len());
    for name in names {
        let entry = params.and_then(|p| p.get(name)).ok_or_else(|| format!("unknown parameter `{name}`"))?;
        let mut path = vec![Seg::Key("parameters".into()), Seg::Key(name.clone())];
        if entry.is_table_like() {
            path.push(Seg::Key("value".into()));
        }
        edits.push(Edit { op: None, path, value: serde_json::Value::from(values[name]) });
    }
    apply(text, &edits)
}

fn numbers(v: &TValue) -> Option<Vec<f64>> {
    let a = v.as_array()?;
    a.iter().map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64))).collect()
}

fn point_list(item: Option<&Item>, dim: usize) -> Option<Vec<Vec<f64>>> {
    let arr = item?.as_array()?;
    arr.iter().map(|p| numbers(p).filter(|v| v.len() == dim)).collect()
}

/// Draggable items of the scene text: control points of `bspline`/`polyline` curves (3D)
/// and of trim curves (`bspline`/`polygon` in (u, v), circle centres).
pub fn editables(text: &str) -> Value {
    let Ok(doc) = text.parse::<DocumentMut>() else { return json!({"handles": [], "trims": []}) };
    let mut handles = Vec::new();
    if let Some(curves) = doc.get("curves").and_then(|c| c.as_table_like()) {
        for (name, c) in curves.iter() {
            for key in ["bspline", "polyline"] {
                if let Some(pts) = point_list(c.get(key), 3) {
                    for (i, p) in pts.iter().enumerate() {
                        handles
                            .push(json!({"curve": name, "index": i, "position": p, "path": ["curves", name, key, i]}));
                    }
                }
            }
        }
    }
    let mut trims = Vec::new();
    if let Some(patches) = doc.get("patches").and_then(|c| c.as_table_like()) {
        for (pname, p) in patches.iter() {
            let Some(curves) = p.get("trim").and_then(|t| t.get("curves")).and_then(|c| c.as_table_like()) else {
                continue;
            };
            for (cname, c) in curves.iter() {
                for key in ["bspline", "polygon"] {
                    if let Some(pts) = point_list(c.get(key), 2) {
                        trims.push(json!({"patch": pname, "curve": cname, "kind": key, "points": pts,
                            "path": ["patches", pname, "trim", "curves", cname, key]}));
                    }
                }
                if let Some(center) =
                    c.get("circle").and_then(|ci| ci.get("center")).and_then(|x| x.as_value()).and_then(numbers)
                {
                    trims.push(json!({"patch": pname, "curve": cname, "kind": "circle", "points": [center],
                        "path": ["patches", pname, "trim", "curves", cname, "circle", "center"]}));
                }
            }
        }
    }
    json!({"handles": handles, "trims": trims})
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edit(op: &str, path: Value, value: Value) -> Edit {
        serde_json::from_value(json!({"op": op, "path": path, "value": value})).unwrap()
    }

    #[test]
    fn edits_keep_comments_and_reach_nested_arrays() {
        let text = "# top\n[curves.c]\nbspline = [[0, 0, 0], [1, 0, 0], [1, 1, 0]] # pts\n";
        let out = apply(text, &[edit("set", json!(["curves", "c", "bspline", 1]), json!([2.5, 0, 0]))]).unwrap();
        assert!(out.contains("# top") && out.contains("2.5"), "{out}");
        let out = apply(&out, &[edit("insert", json!(["curves", "c", "bspline", 0]), json!([9, 9, 9]))]).unwrap();
        let out = apply(&out, &[edit("delete", json!(["curves", "c", "bspline", 3]), Value::Null)]).unwrap();
        let h = editables(&out)["handles"].clone();
        assert_eq!(h.as_array().unwrap().len(), 3);
        assert_eq!(h[0]["position"], json!([9.0, 9.0, 9.0]));
        let e = apply(text, &[edit("set", json!(["curves", "d", "bspline", 0]), json!([0, 0, 0]))]).unwrap_err();
        assert!(e.contains("no such entry `d`"), "{e}");
        let e = apply(text, &[edit("delete", json!(["curves", "c", "bspline", 7]), Value::Null)]).unwrap_err();
        assert!(e.contains("index 7 of an array of 3"), "{e}");
    }

    /// The editor's click on a hole: a fill patch added, in a scene with patches or without
    /// (its `[patches]` table made); a name taken, a bad path or value refused.
    #[test]
    fn a_fill_edit_adds_a_fill_of_the_hole() {
        let text = "# the model\n[import.box]\nstep = \"box.step\"\n";
        let out = apply(text, &[edit("fill", json!(["patches", "f1"]), json!("box.hole1"))]).unwrap();
        assert_eq!(out, format!("{text}\n[patches.f1]\nkind = \"fill\"\nhole = \"box.hole1\"\norder = 6\n"));
        let out2 = apply(&out, &[edit("fill", json!(["patches", "f2"]), json!("box.hole2"))]).unwrap();
        assert!(
            out2.starts_with(&out) && out2.contains("[patches.f2]\nkind = \"fill\"\nhole = \"box.hole2\""),
            "{out2}"
        );
        let e = apply(&out, &[edit("fill", json!(["patches", "f1"]), json!("box.hole3"))]).unwrap_err();
        assert!(e.contains("the patch `f1` exists"), "{e}");
        let e = apply(text, &[edit("fill", json!(["curves", "f1"]), json!("box.hole3"))]).unwrap_err();
        assert!(e.contains("[\"patches\", NAME]"), "{e}");
        let e = apply(text, &[edit("fill", json!(["patches", "f1"]), json!(3))]).unwrap_err();
        assert!(e.contains("the hole's name"), "{e}");
    }

    /// A parameter set in the text resolves as the same override does, bit for bit, in
    /// both of its written forms (a bare value or expression, a table with a range).
    #[test]
    fn parameters_written_into_the_text_resolve_as_overrides() {
        let text = "[parameters]\nr = 2\nk = \"2*r\"\na = { value = 1.0, min = 0.1, max = 3.0 }\n\
                    [curves.c]\nexpr = [\"r*cos(v)\", \"k*sin(v)\", \"a\"]\n";
        let mut values = std::collections::HashMap::new();
        values.insert("a".to_string(), 0.1 + 0.2);
        values.insert("k".to_string(), 1.0 / 3.0);
        let out = with_parameters(text, &values).unwrap();
        let written = super::super::Scene::parse(&out, "t", "t", &Default::default()).unwrap();
        let overridden = super::super::Scene::parse(text, "t", "t", &values).unwrap();
        for name in ["r", "k", "a"] {
            assert_eq!(written.params[name].value.to_bits(), overridden.params[name].value.to_bits(), "{name}");
        }
        assert_eq!(written.params["a"].min, Some(0.1), "{out}");
        let e = with_parameters(text, &[("b".to_string(), 1.0)].into_iter().collect()).unwrap_err();
        assert!(e.contains("unknown parameter `b`"), "{e}");
    }

    /// Regression: JSON integers became TOML floats, so editing `resolution` (integers
    /// only) always failed.
    #[test]
    fn integers_stay_integers() {
        let text = "[patches.p]\nresolution = [10, 10]\n";
        let out = apply(text, &[edit("set", json!(["patches", "p", "resolution"]), json!([20, 30]))]).unwrap();
        assert!(out.contains("resolution = [20, 30]"), "{out}");
        let out = apply(text, &[edit("set", json!(["patches", "p", "a"]), json!(1.5))]).unwrap();
        assert!(out.contains("a = 1.5"), "{out}");
    }
}
