//! Fuzz tests of every parser (issue 14): scene TOML, OBJ/MTL, PLY (ASCII, binary, gzip) and
//! BPT. The shipped files of `scenes/` and `scenes/models/` (the big models replaced by small
//! stand-ins of the same format, so that a case takes milliseconds) and small synthetic ones
//! are mutated by a seeded RNG — bytes flipped, inserted and cut, lines deleted, duplicated and
//! swapped, tokens replaced by hostile ones (`nan`, `1e39`, `-1`, `4294967295`, `f`, `3 3`, …)
//! — and random bytes are fed as well. Every case must return (Ok or an error naming the file)
//! without a panic, within a time bound; the whole file runs in a few seconds.
//!
//! A failure prints the seed and the case; `FUZZ_SEED=N` replays a run, `FUZZ_CASES=N` runs N
//! cases per input instead of the default.

use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use gpgpu_rt::scene::{bpt, obj, ply, Scene};

/// The longest one case may take (a parse of at most a few hundred KB on a busy CI machine).
const CASE_LIMIT: Duration = Duration::from_secs(5);
/// The longest one test may take.
const TEST_LIMIT: Duration = Duration::from_secs(60);

fn cases() -> usize {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(60)
}

fn seed() -> u64 {
    std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(14)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

const HOSTILE: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "1e-45",
    "-1",
    "0",
    "-0",
    "1",
    "3",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "99999999999",
    "",
    " ",
    "3 3",
    "f",
    "v",
    "l",
    "p",
    "[[object]]",
    "[camera]",
    "\"",
    "=",
    "[",
    "]",
    "#",
    "/",
    "//",
    "1/2/3",
    "-2147483648",
    "mtllib",
    "usemtl",
    "newmtl",
    "element",
    "property",
    "list",
    "end_header",
    "\u{0}",
    "é",
    // inputs that are no regular files (`scene_models` makes the FIFOs): refused, never read
    "\"models/pipe.obj\"",
    "\"/dev/zero\"",
    "\"models\"",
    "pipe.mtl",
];

/// One random change of `data`.
fn mutate_once(rng: &mut fastrand::Rng, data: &mut Vec<u8>) {
    let len = data.len();
    let at = |rng: &mut fastrand::Rng| if len == 0 { 0 } else { rng.usize(0..len) };
    match rng.u8(0..8) {
        0 if len > 0 => {
            let i = at(rng);
            data[i] ^= 1 << rng.u8(0..8);
        }
        1 => {
            let i = at(rng);
            let bytes: Vec<u8> = (0..rng.usize(1..8)).map(|_| rng.u8(..)).collect();
            data.splice(i..i, bytes);
        }
        2 => data.truncate(at(rng)),
        3 => {
            let i = at(rng);
            let j = (i + rng.usize(0..16)).min(len);
            data.drain(i..j);
        }
        _ => mutate_lines(rng, data),
    }
}

/// A change of whole lines or words: delete, duplicate, swap, or a hostile token in place of
/// a word.
fn mutate_lines(rng: &mut fastrand::Rng, data: &mut Vec<u8>) {
    let text = String::from_utf8_lossy(data).into_owned();
    let mut lines: Vec<String> = text.split('\n').map(String::from).collect();
    let n = lines.len();
    let i = rng.usize(0..n);
    match rng.u8(0..4) {
        0 => {
            lines.remove(i);
        }
        1 => lines.insert(i, lines[i].clone()),
        2 => lines.swap(i, rng.usize(0..n)),
        _ => {
            let mut words: Vec<String> = lines[i].split(' ').map(String::from).collect();
            let w = rng.usize(0..words.len());
            words[w] = HOSTILE[rng.usize(0..HOSTILE.len())].to_string();
            lines[i] = words.join(" ");
        }
    }
    *data = lines.join("\n").into_bytes();
}

/// `base` with 1 to 4 random changes, or (one case in ten) random bytes.
fn mutant(rng: &mut fastrand::Rng, base: &[u8]) -> Vec<u8> {
    if rng.u8(0..10) == 0 {
        return (0..rng.usize(0..2048)).map(|_| rng.u8(..)).collect();
    }
    let mut data = base.to_vec();
    for _ in 0..rng.usize(1..5) {
        mutate_once(rng, &mut data);
    }
    data
}

/// Run `cases()` mutants of each base through `parse` (which reads the file it is given),
/// each without a panic and within [`CASE_LIMIT`], the whole within [`TEST_LIMIT`].
fn fuzz<F>(name: &str, bases: Vec<Vec<u8>>, setup: fn(&Path), parse: F)
where
    F: Fn(&Path) -> Result<(), String> + Send + 'static,
{
    // a small memory limit keeps a mutated size (quads = 4294967295 → capped; 3000 → refused
    // here) from building meshes of gigabytes: what the budget refuses is an error like others
    std::env::set_var("GPGPU_RT_MEMORY_LIMIT", "256M");
    let name = name.to_string();
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        let dir = tempfile::tempdir().unwrap();
        setup(dir.path());
        let file = dir.path().join(&name);
        let mut rng = fastrand::Rng::with_seed(seed());
        for (b, base) in bases.iter().enumerate() {
            for case in 0..cases() {
                let data = mutant(&mut rng, base);
                std::fs::File::create(&file)
                    .unwrap()
                    .write_all(&data)
                    .unwrap();
                let t = Instant::now();
                let r = catch_unwind(AssertUnwindSafe(|| parse(&file)));
                let took = t.elapsed();
                let show = String::from_utf8_lossy(&data[..data.len().min(400)]).into_owned();
                let id = format!("{name}: base {b}, case {case} (seed {})", seed());
                assert!(r.is_ok(), "{id} panicked on:\n{show}");
                assert!(took < CASE_LIMIT, "{id} took {took:?} on:\n{show}");
            }
        }
        tx.send(()).unwrap();
    });
    match rx.recv_timeout(TEST_LIMIT) {
        Ok(()) => worker.join().unwrap(),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            std::panic::resume_unwind(worker.join().unwrap_err())
        }
        Err(mpsc::RecvTimeoutError::Timeout) => {
            panic!("the fuzz cases took more than {TEST_LIMIT:?}")
        }
    }
}

fn read(path: &str) -> Vec<u8> {
    std::fs::read(root().join(path)).unwrap()
}

fn gz(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

const CUBE_PLY: &str = "ply\nformat ascii 1.0\ncomment a unit cube\nelement vertex 8\n\
    property float x\nproperty float y\nproperty float z\nelement face 6\n\
    property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n\
    1 0 1\n1 1 1\n0 1 1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";

/// The cube as binary little-endian PLY.
fn cube_binary() -> Vec<u8> {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\n\
        property float y\nproperty float z\nelement face 6\n\
        property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for k in 0..8u32 {
        for axis in [k & 1, (k >> 1) & 1, (k >> 2) & 1] {
            b.extend_from_slice(&(axis as f32).to_le_bytes());
        }
    }
    for face in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [1, 3, 7, 5],
        [0, 4, 6, 2],
    ] {
        b.push(4);
        face.iter()
            .for_each(|i: &i32| b.extend_from_slice(&i.to_le_bytes()));
    }
    b
}

/// The models the shipped scenes name, small: the bunny and the dragon replaced by the cow
/// and the cube (their formats kept).
fn scene_models(dir: &Path) {
    let m = dir.join("models");
    std::fs::create_dir_all(&m).unwrap();
    let cow = read("scenes/models/cow.obj");
    std::fs::write(m.join("cow.obj"), &cow).unwrap();
    std::fs::write(m.join("stanford-bunny.obj"), &cow).unwrap();
    std::fs::write(m.join("teapot.bpt"), read("scenes/models/teapot.bpt")).unwrap();
    std::fs::write(m.join("dragon_vrip_res2.ply.gz"), gz(CUBE_PLY.as_bytes())).unwrap();
    // the streaming tracer's models are small: themselves
    for name in [
        "knight_standin.obj",
        "torus_knot.obj",
        "closed_box.obj",
        "bunny_low.obj",
    ] {
        let path = format!("scenes/models/{name}");
        std::fs::write(m.join(name), read(&path)).unwrap();
    }
    fifos(&m);
}

/// FIFOs where a mutated path may point: read without a bound, they would block for ever.
fn fifos(dir: &Path) {
    for name in ["pipe.obj", "pipe.mtl"] {
        let c = std::ffi::CString::new(dir.join(name).to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    }
}

/// Each kind of input file as a FIFO, a device and a folder: refused at once, naming it.
#[test]
fn inputs_that_are_no_regular_files() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("models");
    std::fs::create_dir(&m).unwrap();
    fifos(&m);
    std::fs::write(
        m.join("t.obj"),
        "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let head = "[camera]\nposition = [0, 1, 3]\nlook_at = [0, 0, 0]\n[[object]]\n";
    for (object, named) in [
        ("type = \"obj\"\npath = \"models/pipe.obj\"", "pipe.obj"),
        ("type = \"obj\"\npath = \"/dev/zero\"", "/dev/zero"),
        ("type = \"obj\"\npath = \"models\"", "models"),
        ("type = \"obj\"\npath = \"models/t.obj\"", "pipe.mtl"),
        ("type = \"ply\"\npath = \"models/pipe.obj\"", "pipe.obj"),
        ("type = \"teapot\"\npath = \"/dev/zero\"", "/dev/zero"),
        (
            "type = \"floor\"\ntexture = \"models/pipe.obj\"",
            "pipe.obj",
        ),
    ] {
        let s = d.path().join("s.toml");
        std::fs::write(&s, format!("{head}{object}\n")).unwrap();
        let t = Instant::now();
        let e = Scene::load(&s).expect_err(object).to_string();
        assert!(t.elapsed() < CASE_LIMIT, "{object}: {:?}", t.elapsed());
        assert!(
            e.contains(named) && e.contains("regular files"),
            "{object}: {e}"
        );
    }
}

#[test]
fn scene_files() {
    let mut bases = Vec::new();
    for e in std::fs::read_dir(root().join("scenes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            bases.push(std::fs::read(&p).unwrap());
        }
    }
    bases.sort();
    assert!(bases.len() >= 10, "the shipped scenes");
    fuzz("scene.toml", bases, scene_models, |p| {
        Scene::load(p).map(|_| ()).map_err(|e| e.to_string())
    });
}

fn mtl_file(dir: &Path) {
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl red\nKa 0 0 0\nKd 0.8 0.1 0.1\nKs 0.5 0.5 0.5\nNs 20\nd 1\nillum 2\n\
         newmtl blue\nKd 0.1 0.1 0.8\n",
    )
    .unwrap();
}

#[test]
fn obj_files() {
    let cow = read("scenes/models/cow.obj");
    let bunny: Vec<u8> = {
        // the bunny's first 3000 vertices and the faces among them
        let text = String::from_utf8(read("scenes/models/stanford-bunny.obj")).unwrap();
        let keep = |l: &&str| {
            !l.starts_with("f ")
                || l.split_whitespace().skip(1).all(|c| {
                    c.split('/')
                        .next()
                        .unwrap()
                        .parse::<u32>()
                        .is_ok_and(|i| i <= 3000)
                })
        };
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.starts_with("v "))
            .filter(keep)
            .collect();
        let verts: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("v "))
            .take(3000)
            .collect();
        format!("{}\n{}\n", verts.join("\n"), lines.join("\n")).into_bytes()
    };
    let small = b"mtllib m.mtl\no quad\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\n\
        v 0 1 0 1 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl red\n\
        f 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl blue\nf -4//1 -2//1 -1//1\nl 1 2\n"
        .to_vec();
    fuzz("o.obj", vec![cow, bunny, small], mtl_file, |p| {
        obj::load_obj(p).map(|_| ()).map_err(|e| e.to_string())
    });
}

#[test]
fn mtl_files() {
    let mtl = b"newmtl red\nKa 0 0 0\nKd 0.8 0.1 0.1\nKs 0.5 0.5 0.5\nNs 20\nd 1\nTr 0\nillum 2\n\
        map_Kd tex.png\nnewmtl blue\nKd 0.1 0.1 0.8\n"
        .to_vec();
    fn obj_file(dir: &Path) {
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
        std::fs::write(dir.join("o.obj"), obj).unwrap();
    }
    fuzz("m.mtl", vec![mtl], obj_file, |p| {
        let o = p.with_file_name("o.obj");
        obj::load_obj(&o).map(|_| ()).map_err(|e| e.to_string())
    });
}

#[test]
fn ply_files() {
    let dragon_head: Vec<u8> = {
        // the dragon's header and the start of its data (its counts then claim more)
        let gz = read("scenes/models/dragon_vrip_res2.ply.gz");
        let mut d = flate2::read::GzDecoder::new(&gz[..]);
        let mut buf = vec![0u8; 4096];
        std::io::Read::read_exact(&mut d, &mut buf).unwrap();
        buf
    };
    let bases = vec![CUBE_PLY.as_bytes().to_vec(), cube_binary(), dragon_head];
    fuzz(
        "m.ply",
        bases.clone(),
        |_| {},
        |p| ply::load_ply(p).map(|_| ()).map_err(|e| e.to_string()),
    );
    // gzip: the mutated PLY compressed (the decompressor sees a valid stream), and the
    // compressed bytes mutated
    let gzipped: Vec<Vec<u8>> = bases.iter().map(|b| gz(b)).collect();
    fuzz(
        "m.ply.gz",
        gzipped,
        |_| {},
        |p| ply::load_ply(p).map(|_| ()).map_err(|e| e.to_string()),
    );
}

#[test]
fn bpt_files() {
    let teapot = read("scenes/models/teapot.bpt");
    let one = {
        let text = String::from_utf8(teapot.clone()).unwrap();
        let lines: Vec<&str> = text.lines().skip(1).take(17).collect();
        format!("1\n{}\n", lines.join("\n")).into_bytes()
    };
    fuzz(
        "t.bpt",
        vec![teapot, one],
        |_| {},
        |p| bpt::teapot(p, 4).map(|_| ()).map_err(|e| e.to_string()),
    );
}

/// glTF: mutants of the shipped GLB (its JSON chunk and binary chunk) and of a small JSON file
/// with a data-URI buffer, through the loader and the triangle count.
#[test]
fn gltf_files() {
    let glb = read("scenes/models/cow.glb");
    let pos: String = {
        use base64::Engine as _;
        let p: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        base64::engine::general_purpose::STANDARD.encode(p)
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0,"translation":[1,2,3],"children":[1]}},{{"camera":0,"rotation":[0,0,0,1]}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.1}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5121,"count":3,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":1,"byteLength":3}}],
"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{pos}"}},
{{"byteLength":3,"uri":"data:application/octet-stream;base64,AAEC"}}]}}"#
    );
    let load = |p: &Path| {
        gpgpu_rt::scene::gltf::count_triangles(p).map_err(|e| e.to_string())?;
        gpgpu_rt::scene::gltf::load(p)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    fuzz("m.glb", vec![glb], |_| {}, load);
    fuzz("m.gltf", vec![json.into_bytes()], |_| {}, load);
}
