//! glTF 2.0 binary (`.glb`), with morph-target animation for meshes that carry one.

use pdeshape_core::Vec3;
use pdeshape_core::mesh::Mesh;
use serde_json::{Value, json};
use std::io::{self, Write};

struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn align(&mut self) {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
    }

    /// Appends f32 tuples and returns the accessor index.
    fn floats(&mut self, items: &[Vec<f32>], kind: &str, with_bounds: bool, target: Option<u32>) -> usize {
        self.align();
        let offset = self.data.len();
        let width = items.first().map(|v| v.len()).unwrap_or(1);
        let mut lo = vec![f32::INFINITY; width];
        let mut hi = vec![f32::NEG_INFINITY; width];
        for it in items {
            for (k, &x) in it.iter().enumerate() {
                self.data.extend_from_slice(&x.to_le_bytes());
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
        }
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": self.data.len() - offset});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.views.push(view);
        let mut acc = json!({
            "bufferView": self.views.len() - 1, "componentType": 5126,
            "count": items.len(), "type": kind
        });
        if with_bounds && !items.is_empty() {
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn indices(&mut self, idx: &[u32]) -> usize {
        self.align();
        let offset = self.data.len();
        for i in idx {
            self.data.extend_from_slice(&i.to_le_bytes());
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": self.data.len() - offset, "target": 34963}));
        self.accessors.push(
            json!({"bufferView": self.views.len() - 1, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }
}

fn v3(p: &[Vec3]) -> Vec<Vec<f32>> {
    p.iter().map(|q| vec![q.x as f32, q.y as f32, q.z as f32]).collect()
}

/// Writes meshes as a glTF 2.0 binary: one node and mesh per patch (named), positions,
/// normals, `TEXCOORD_0`, scalar fields as application attributes (`_NAME`), and, for a mesh
/// with a [`pdeshape_core::mesh::MorphAnimation`], one morph target per frame plus an
/// animation that steps the weights through the frames (linear interpolation between
/// neighbouring frames).
pub fn write_glb(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    let mut bin = Bin { data: Vec::new(), views: Vec::new(), accessors: Vec::new() };
    let mut gl_meshes = Vec::new();
    let mut nodes = Vec::new();
    let mut materials = Vec::new();
    let mut animations = Vec::new();
    for (k, m) in meshes.iter().enumerate() {
        let mut attrs = serde_json::Map::new();
        attrs.insert("POSITION".into(), json!(bin.floats(&v3(&m.positions), "VEC3", true, Some(34962))));
        if !m.normals.is_empty() {
            attrs.insert("NORMAL".into(), json!(bin.floats(&v3(&m.normals), "VEC3", false, Some(34962))));
        }
        if !m.uvs.is_empty() {
            let uv: Vec<Vec<f32>> = m.uvs.iter().map(|t| vec![t[0] as f32, t[1] as f32]).collect();
            attrs.insert("TEXCOORD_0".into(), json!(bin.floats(&uv, "VEC2", false, Some(34962))));
        }
        for f in &m.fields {
            let vals: Vec<Vec<f32>> = f.values.iter().map(|x| vec![*x as f32]).collect();
            let name = format!("_{}", f.name.to_ascii_uppercase().replace(|c: char| !c.is_ascii_alphanumeric(), "_"));
            attrs.insert(name, json!(bin.floats(&vals, "SCALAR", false, Some(34962))));
        }
        let tris: Vec<u32> = m.all_triangles().into_iter().flatten().collect();
        let ind = bin.indices(&tris);
        let color = [0.75, 0.78, 0.85, 1.0];
        materials.push(json!({
            "name": format!("{}-material", m.name),
            "doubleSided": true,
            "pbrMetallicRoughness": {"baseColorFactor": color, "metallicFactor": 0.1, "roughnessFactor": 0.6}
        }));
        let mut prim = json!({"attributes": attrs, "indices": ind, "mode": 4, "material": k});
        let mut mesh = json!({"name": m.name, "primitives": []});
        if let Some(anim) = m.animation.as_ref().filter(|a| !a.positions.is_empty()) {
            let mut targets = Vec::new();
            for (f, pos) in anim.positions.iter().enumerate() {
                let dp: Vec<Vec3> = pos.iter().zip(&m.positions).map(|(a, b)| *a - *b).collect();
                let mut t = serde_json::Map::new();
                t.insert("POSITION".into(), json!(bin.floats(&v3(&dp), "VEC3", true, Some(34962))));
                if let (Some(nf), false) = (anim.normals.get(f), m.normals.is_empty()) {
                    let dn: Vec<Vec3> = nf.iter().zip(&m.normals).map(|(a, b)| *a - *b).collect();
                    t.insert("NORMAL".into(), json!(bin.floats(&v3(&dn), "VEC3", false, Some(34962))));
                }
                targets.push(Value::Object(t));
            }
            let n = targets.len();
            prim["targets"] = json!(targets);
            let mut w0 = vec![0.0f32; n];
            w0[0] = 1.0;
            mesh["weights"] = json!(w0);
            mesh["extras"] = json!({"targetNames": anim.times.iter().map(|t| format!("t={t}")).collect::<Vec<_>>()});
            let times: Vec<Vec<f32>> = anim.times.iter().map(|t| vec![*t as f32]).collect();
            let input = bin.floats(&times, "SCALAR", true, None);
            let weights: Vec<Vec<f32>> =
                (0..n).flat_map(|f| (0..n).map(move |j| vec![if j == f { 1.0 } else { 0.0 }])).collect();
            let output = bin.floats(&weights, "SCALAR", false, None);
            animations.push(json!({
                "name": format!("{}-animation", m.name),
                "samplers": [{"input": input, "output": output, "interpolation": "LINEAR"}],
                "channels": [{"sampler": 0, "target": {"node": k, "path": "weights"}}]
            }));
        }
        mesh["primitives"] = json!([prim]);
        gl_meshes.push(mesh);
        nodes.push(json!({"name": m.name, "mesh": k}));
    }
    bin.align();
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "pdeshape"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": gl_meshes,
        "materials": materials,
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.data.len()}],
    });
    if !animations.is_empty() {
        doc["animations"] = json!(animations);
    }
    let mut text = serde_json::to_vec(&doc).map_err(io::Error::other)?;
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.data.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&text)?;
    w.write_all(&(bin.data.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin.data)?;
    Ok(())
}
