//! Simplify the Stanford bunny with meshoptimizer's simplifier (meshopt crate) to a target
//! triangle count; writes an OBJ. Usage: simplify-bunny IN.obj OUT.obj TARGET_TRIANGLES
use std::io::Write;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (input, output, target): (&str, &str, usize) = (&a[1], &a[2], a[3].parse().unwrap());
    let (models, _) = tobj::load_obj(input, &tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() }).unwrap();
    let m = &models[0].mesh;
    let verts: Vec<[f32; 3]> = m.positions.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    let adapter = meshopt::VertexDataAdapter::new(bytemuck_cast(&verts), 12, 0).unwrap();
    // search the target error / index count so the result has exactly `target` triangles if it can
    let mut best: Option<Vec<u32>> = None;
    for slack in 0..400 {
        let want = (target + slack) * 3;
        let idx = meshopt::simplify(&m.indices, &adapter, want, 1.0, meshopt::SimplifyOptions::None, None);
        let tris = idx.len() / 3;
        eprintln!("asked {} got {}", want / 3, tris);
        if tris <= target { best = Some(idx); if tris == target { break; } } else { break; }
    }
    let idx = best.unwrap();
    // compact vertices
    let mut map = vec![u32::MAX; verts.len()];
    let mut out_v = Vec::new();
    let mut out_i = Vec::new();
    for &i in &idx {
        if map[i as usize] == u32::MAX { map[i as usize] = out_v.len() as u32; out_v.push(verts[i as usize]); }
        out_i.push(map[i as usize]);
    }
    let mut f = std::io::BufWriter::new(std::fs::File::create(output).unwrap());
    writeln!(f, "# {} vertices, {} triangles", out_v.len(), out_i.len() / 3).unwrap();
    for v in &out_v { writeln!(f, "v {:.6} {:.6} {:.6}", v[0], v[1], v[2]).unwrap(); }
    for t in out_i.chunks(3) { writeln!(f, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap(); }
    eprintln!("wrote {} triangles", out_i.len() / 3);
}

fn bytemuck_cast(v: &[[f32; 3]]) -> &[u8] {
    unsafe { std::slice::from_raw_parts(v.as_ptr() as *const u8, v.len() * 12) }
}
