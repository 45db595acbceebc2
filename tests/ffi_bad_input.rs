//! Bad-input sweep through the C ABI (SPEC 3.9, 4, 6.2): every exported function of `include/kodawari.h`
//! gets every pointer argument NULL in turn, every float argument NaN / +Inf / -Inf (and a huge value
//! where that is out of range), every id 0 / stale / foreign / of the wrong kind, counts and capacities
//! too small, and `struct_size` wrong.
//!
//! Each rejected call must return its documented status (never OK, never PANIC), leave a non-empty
//! `kdw_last_error_message`, leave `kdw_engine_state_hash` of every engine bit-identical, and leave every
//! output untouched (outputs are filled with a sentinel before the call).
//!
//! The header is parsed at test time: every function and each of its parameters must be covered by the
//! case table (`null:<param>`, `nan:<param>`, `stale:<param>`, ...), so a new function or parameter
//! without coverage fails `every_header_function_is_covered`.

#![allow(clippy::type_complexity)]

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::{CStr, c_char};
use std::ptr::{null, null_mut};

use kodawari::ffi::batch::*;
use kodawari::ffi::chain::*;
use kodawari::ffi::collider::*;
use kodawari::ffi::engine::*;
use kodawari::ffi::sketch::*;
use kodawari::ffi::status::*;
use kodawari::ffi::types::*;
use kodawari::ffi::version::*;
use kodawari::ffi::view_shape::*;

const N: u32 = 5;
const SENTINEL_F: f32 = 12345.678;
const SENTINEL_U32: u32 = 0xDEAD_BEEF;
const SENTINEL_U64: u64 = 0xDEAD_BEEF_CAFE_F00D;
const MARKER: &str = "7777777";

// ---- header parsing -----------------------------------------------------------------------------------

#[derive(Debug, Clone)]
struct Param {
    ty: String,
    name: String,
    pointer: bool,
    is_const: bool,
}

#[derive(Debug)]
struct Function {
    name: String,
    returns: String,
    params: Vec<Param>,
}

fn header_text() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/kodawari.h")).expect("read kodawari.h")
}

/// The header without comments and preprocessor lines.
fn strip(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find("/*") {
        out.push_str(&rest[..start]);
        rest = &rest[start + 2..];
        rest = &rest[rest.find("*/").map_or(rest.len(), |e| e + 2)..];
    }
    out.push_str(rest);
    out.lines()
        .map(|l| if let Some(i) = l.find("//") { &l[..i] } else { l })
        .filter(|l| !l.trim_start().starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n")
}

fn last_identifier(s: &str) -> String {
    let s = s.trim_end();
    let start = s.rfind(|c: char| !(c.is_alphanumeric() || c == '_')).map_or(0, |i| i + 1);
    s[start..].to_string()
}

fn parse_functions(text: &str) -> Vec<Function> {
    let clean = strip(text).replace("extern \"C\" {", "");
    let mut functions = Vec::new();
    for statement in clean.split(';') {
        let statement = statement.trim().trim_start_matches('}').trim();
        let Some(open) = statement.find('(') else { continue };
        let name = last_identifier(&statement[..open]);
        if !name.starts_with("kdw_") || statement.starts_with("typedef") {
            continue;
        }
        let returns = statement[..open].trim_end().trim_end_matches(&name).trim().to_string();
        let close = statement.rfind(')').expect("closing parenthesis");
        let params = statement[open + 1..close]
            .split(',')
            .map(str::trim)
            .filter(|p| !p.is_empty() && *p != "void")
            .map(|p| {
                let name = last_identifier(p);
                let ty = p[..p.len() - name.len()].trim().to_string();
                Param { pointer: ty.contains('*'), is_const: ty.starts_with("const"), ty, name }
            })
            .collect();
        functions.push(Function { name, returns, params });
    }
    functions
}

/// Float fields of the def structs (`struct_name -> [field]`), vec3 fields expanded to `field.x` etc. and
/// transform fields to `field.position.x` ... `field.rotation.w`.
fn struct_float_fields(text: &str) -> BTreeMap<String, Vec<String>> {
    let clean = strip(text);
    let mut map = BTreeMap::new();
    let mut rest = clean.as_str();
    while let Some(start) = rest.find("typedef struct ") {
        rest = &rest[start + "typedef struct ".len()..];
        let Some(open) = rest.find('{') else { break };
        if rest[..open].contains(';') {
            // An opaque `typedef struct x x;`.
            continue;
        }
        let name = rest[..open].trim().to_string();
        let close = rest.find('}').expect("struct end");
        let mut fields = Vec::new();
        for field in rest[open + 1..close].split(';') {
            let field = field.trim();
            let id = last_identifier(field);
            if field.starts_with("uint32_t struct_size") {
                fields.push("@struct_size".into());
            } else if field.starts_with("float ") {
                fields.push(id);
            } else if field.starts_with("struct kdw_vec3 ") {
                fields.extend(["x", "y", "z"].map(|c| format!("{id}.{c}")));
            } else if field.starts_with("struct kdw_transform ") {
                fields.extend(["position.x", "position.y", "position.z"].map(|c| format!("{id}.{c}")));
                fields.extend(["rotation.x", "rotation.y", "rotation.z", "rotation.w"].map(|c| format!("{id}.{c}")));
            }
        }
        map.insert(name, fields);
        rest = &rest[close..];
    }
    map
}

/// The coverage tags the header demands of a function.
fn required_tags(f: &Function, floats: &BTreeMap<String, Vec<String>>) -> BTreeSet<String> {
    let mut tags = BTreeSet::new();
    if f.returns != "kdw_status" {
        tags.insert("call".to_string());
        return tags;
    }
    for p in &f.params {
        let n = &p.name;
        if p.pointer {
            tags.insert(format!("null:{n}"));
        }
        if p.ty == "float" {
            for v in ["nan", "inf", "-inf"] {
                tags.insert(format!("{v}:{n}"));
            }
        }
        if p.ty == "kdw_chain_id" || p.ty == "kdw_view_shape_id" || p.ty == "kdw_collider_id" {
            for v in ["zero", "stale", "foreign", "kind"] {
                tags.insert(format!("{v}:{n}"));
            }
        }
        if p.ty == "uint32_t" && (n.contains("count") || n.contains("capacity")) {
            tags.insert(format!("count:{n}"));
        }
        if p.pointer && p.is_const {
            let base =
                p.ty.trim_start_matches("const").trim().trim_start_matches("struct").trim().trim_end_matches('*');
            let base = base.trim();
            if base == "kdw_vec2" || base == "kdw_vec3" || base == "kdw_transform" {
                for v in ["nan", "inf", "-inf"] {
                    tags.insert(format!("{v}:{n}"));
                }
            }
            // Def structs (those with a `struct_size`): a wrong size and each float field non-finite.
            let fields = floats.get(base).cloned().unwrap_or_default();
            if fields.iter().any(|f| f == "@struct_size") {
                tags.insert(format!("struct_size:{n}"));
                for field in fields.iter().filter(|f| !f.starts_with('@')) {
                    for v in ["nan", "inf", "-inf"] {
                        tags.insert(format!("{v}:{n}.{field}"));
                    }
                }
            }
        }
    }
    tags
}

// ---- fixture ------------------------------------------------------------------------------------------

struct Fixture {
    a: *mut kdw_engine,
    b: *mut kdw_engine,
    chain: u64,
    view: u64,
    stale_chain: u64,
    stale_view: u64,
    foreign_chain: u64,
    foreign_view: u64,
    /// Colliders of `a`: a sphere and a capsule out of the chains' reach (2 m to the side), so that they are
    /// part of the state every rejected call must leave alone without changing what the chains do.
    collider: u64,
    stale_collider: u64,
    foreign_collider: u64,
    joint_total: u32,
    chain_total: u32,
    collider_total: u32,
}

fn ok(status: kdw_status, what: &str) {
    assert_eq!(status, KDW_STATUS_OK, "{what}: {}", last_error());
}

fn last_error() -> String {
    let mut buffer = [0 as c_char; 512];
    let mut length = 0u32;
    kdw_last_error_message(buffer.as_mut_ptr(), buffer.len() as u32, &mut length);
    // SAFETY: NUL-terminated by kdw_last_error_message.
    unsafe { CStr::from_ptr(buffer.as_ptr()) }.to_string_lossy().into_owned()
}

fn joints(n: u32, bend: f32) -> Vec<kdw_transform> {
    (0..n)
        .map(|i| kdw_transform {
            position: kdw_vec3 { x: bend * i as f32 * i as f32 * 0.01, y: -0.05 * i as f32, z: 0.0 },
            rotation: kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
        })
        .collect()
}

fn vec3(x: f32, y: f32, z: f32) -> kdw_vec3 {
    kdw_vec3 { x, y, z }
}

fn head() -> kdw_transform {
    kdw_transform { position: vec3(0.0, 1.6, 0.0), rotation: kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } }
}

fn camera() -> kdw_vec3 {
    vec3(0.0, 1.7, 3.0)
}

fn new_engine() -> *mut kdw_engine {
    let def = kdw_engine_def_default();
    let mut engine = null_mut();
    ok(kdw_engine_create(&def, &mut engine), "create engine");
    engine
}

fn new_chain(engine: *mut kdw_engine, n: u32) -> u64 {
    let def = kdw_chain_def_default();
    let base = joints(n, 0.0);
    let mut id = 0;
    ok(kdw_chain_create(engine, &def, base.as_ptr(), n, &mut id), "create chain");
    id
}

/// A valid collider def of `shape`, posed out of the fixture chains' reach.
fn collider_def(shape: u32, radius: f32, half_height: f32) -> kdw_collider_def {
    let transform = kdw_transform { position: vec3(2.0, 1.4, 0.0), ..head() };
    kdw_collider_def { shape, radius, half_height, transform, ..kdw_collider_def_default() }
}

fn new_collider(engine: *mut kdw_engine, def: &kdw_collider_def) -> u64 {
    let mut id = 0;
    ok(kdw_collider_create(engine, def, &mut id), "create collider");
    id
}

/// Valid poses for the fixture's two colliders (one entry per collider, creation order).
fn collider_poses() -> [kdw_transform; 2] {
    [
        kdw_transform { position: vec3(2.0, 1.4, 0.0), ..head() },
        kdw_transform { position: vec3(-2.0, 1.4, 0.0), ..head() },
    ]
}

fn new_view(engine: *mut kdw_engine, chain: u64, n: u32) -> u64 {
    let shape = joints(n, 1.0);
    let mut id = 0;
    ok(kdw_chain_add_view_shape(engine, chain, &vec3(1.0, 0.0, 0.0), shape.as_ptr(), n, 2.0, &mut id), "view");
    id
}

impl Fixture {
    fn new() -> Self {
        let a = new_engine();
        let b = new_engine();
        let chain = new_chain(a, N);
        let view = new_view(a, chain, N);
        let second = new_chain(a, N);
        new_view(a, second, N);
        let stale_chain = new_chain(a, N);
        let stale_view = new_view(a, second, N);
        ok(kdw_view_shape_remove(a, stale_view), "remove view");
        ok(kdw_chain_destroy(a, stale_chain), "destroy chain");
        let foreign_chain = new_chain(b, N);
        let foreign_view = new_view(b, foreign_chain, N);
        let collider = new_collider(a, &collider_def(KDW_COLLIDER_SPHERE, 0.1, 0.0));
        let stale_collider = new_collider(a, &collider_def(KDW_COLLIDER_SPHERE, 0.2, 0.0));
        new_collider(a, &collider_def(KDW_COLLIDER_CAPSULE, 0.05, 0.1));
        ok(kdw_collider_destroy(a, stale_collider), "destroy collider");
        let foreign_collider = new_collider(b, &collider_def(KDW_COLLIDER_SPHERE, 0.1, 0.0));
        ok(kdw_engine_set_collider_transforms(a, collider_poses().as_ptr(), 2), "move colliders");
        for _ in 0..10 {
            ok(kdw_engine_step(a, 1.0 / 60.0, &camera(), &head()), "step a");
            ok(kdw_engine_step(b, 1.0 / 60.0, &camera(), &head()), "step b");
        }
        Self {
            a,
            b,
            chain,
            view,
            stale_chain,
            stale_view,
            foreign_chain,
            foreign_view,
            collider,
            stale_collider,
            foreign_collider,
            joint_total: 2 * N,
            chain_total: 2,
            collider_total: 2,
        }
    }

    fn hashes(&self) -> (u64, u64) {
        let (mut ha, mut hb) = (0, 0);
        ok(kdw_engine_state_hash(self.a, &mut ha), "hash a");
        ok(kdw_engine_state_hash(self.b, &mut hb), "hash b");
        (ha, hb)
    }

    /// The bad chain ids: null, stale, foreign, and ids of the other kinds (a view shape's, a collider's).
    fn bad_chain_ids(&self) -> [(&'static str, u64); 5] {
        [
            ("zero", 0),
            ("stale", self.stale_chain),
            ("foreign", self.foreign_chain),
            ("kind", self.view),
            ("kind", self.collider),
        ]
    }

    fn bad_view_ids(&self) -> [(&'static str, u64); 5] {
        [
            ("zero", 0),
            ("stale", self.stale_view),
            ("foreign", self.foreign_view),
            ("kind", self.chain),
            ("kind", self.collider),
        ]
    }

    fn bad_collider_ids(&self) -> [(&'static str, u64); 5] {
        [
            ("zero", 0),
            ("stale", self.stale_collider),
            ("foreign", self.foreign_collider),
            ("kind", self.chain),
            ("kind", self.view),
        ]
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        kdw_engine_destroy(self.a);
        kdw_engine_destroy(self.b);
    }
}

// ---- cases --------------------------------------------------------------------------------------------

type Run = Box<dyn Fn(&Fixture) -> (kdw_status, bool)>;

struct Case {
    function: &'static str,
    tag: String,
    expected: kdw_status,
    run: Run,
}

fn case(function: &'static str, tag: impl Into<String>, expected: kdw_status, run: Run) -> Case {
    Case { function, tag: tag.into(), expected, run }
}

/// Calls `f` with an out-pointer to a sentinel; reports whether the sentinel survived.
fn out<T: Copy + PartialEq>(sentinel: T, f: impl FnOnce(*mut T) -> kdw_status) -> (kdw_status, bool) {
    let mut value = sentinel;
    let status = f(&mut value);
    (status, value == sentinel)
}

/// Calls `f` with a sentinel-filled buffer of `len` and a sentinel `out_written`.
fn buffer<T: Copy + PartialEq>(
    sentinel: T,
    len: usize,
    f: impl FnOnce(*mut T, *mut u32) -> kdw_status,
) -> (kdw_status, bool) {
    let mut values = vec![sentinel; len.max(1)];
    let mut written = SENTINEL_U32;
    let status = f(values.as_mut_ptr(), &mut written);
    (status, written == SENTINEL_U32 && values.iter().all(|v| *v == sentinel))
}

fn sentinel_transform() -> kdw_transform {
    kdw_transform {
        position: vec3(SENTINEL_F, SENTINEL_F, SENTINEL_F),
        rotation: kdw_quat { x: SENTINEL_F, y: SENTINEL_F, z: SENTINEL_F, w: SENTINEL_F },
    }
}

fn sentinel_quat() -> kdw_quat {
    kdw_quat { x: SENTINEL_F, y: SENTINEL_F, z: SENTINEL_F, w: SENTINEL_F }
}

/// A value of `T` whose every byte is 0xA5: a sentinel that covers every field, including ones added to the
/// def structs later. Only for the plain C structs here, whose fields are u32 / f32 (any bit pattern is valid;
/// 0xA5A5A5A5 is an ordinary finite float, so `==` compares it reliably).
fn sentinel_bytes<T: Copy>() -> T {
    // SAFETY: `T` is one of the padding-free `kdw_*` structs of u32 and f32 fields, valid for any bit pattern.
    unsafe {
        let mut value = std::mem::MaybeUninit::<T>::uninit();
        std::ptr::write_bytes(value.as_mut_ptr(), 0xA5, 1);
        value.assume_init()
    }
}

fn sentinel_engine_def() -> kdw_engine_def {
    sentinel_bytes()
}

fn sentinel_chain_def() -> kdw_chain_def {
    sentinel_bytes()
}

const BAD_FLOATS: [(&str, f32); 3] = [("nan", f32::NAN), ("inf", f32::INFINITY), ("-inf", f32::NEG_INFINITY)];

/// Bad values for a vec3 argument: each component non-finite in turn.
fn bad_vec3s() -> Vec<(String, kdw_vec3)> {
    let mut out = Vec::new();
    for (tag, v) in BAD_FLOATS {
        for c in 0..3 {
            let mut p = vec3(0.5, 0.25, 1.0);
            match c {
                0 => p.x = v,
                1 => p.y = v,
                _ => p.z = v,
            }
            out.push((tag.to_string(), p));
        }
    }
    out
}

/// Bad single transforms: a non-finite position or rotation component, or a null rotation.
fn bad_transforms() -> Vec<(String, kdw_transform)> {
    let mut out = Vec::new();
    for (tag, v) in BAD_FLOATS {
        let mut t = head();
        t.position.y = v;
        out.push((tag.to_string(), t));
        let mut t = head();
        t.rotation.w = v;
        out.push((tag.to_string(), t));
        let mut t = head();
        t.rotation.x = v;
        out.push((tag.to_string(), t));
    }
    let mut t = head();
    t.rotation = kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 0.0 };
    out.push(("nullquat".into(), t));
    out
}

/// Bad joint arrays of `n` joints: one joint non-finite, a null rotation, a zero-length segment, an
/// overflowing segment.
fn bad_joint_arrays(n: u32) -> Vec<(String, Vec<kdw_transform>)> {
    let mut out = Vec::new();
    for (tag, t) in bad_transforms() {
        for k in [0usize, n as usize - 1] {
            let mut j = joints(n, 0.0);
            j[k].position = vec3(j[k].position.x, j[k].position.y + t.position.y - 1.6, j[k].position.z);
            j[k].rotation = t.rotation;
            out.push((tag.clone(), j));
        }
    }
    let mut zero = joints(n, 0.0);
    zero[2] = zero[1];
    out.push(("zero-segment".into(), zero));
    let mut huge = joints(n, 0.0);
    huge[n as usize - 1].position.x = 1e30;
    out.push(("huge".into(), huge));
    let mut huge = joints(n, 0.0);
    huge[1].position.y = -1e30;
    out.push(("huge".into(), huge));
    out
}

fn engine_def_variants() -> Vec<(String, kdw_engine_def, kdw_status)> {
    let d = kdw_engine_def_default();
    let mut out = Vec::new();
    for size in [0u32, d.struct_size - 4, d.struct_size + 4, u32::MAX] {
        out.push(("struct_size:{}".into(), kdw_engine_def { struct_size: size, ..d }, KDW_STATUS_STRUCT_SIZE_MISMATCH));
    }
    let fields: [(&str, fn(&mut kdw_engine_def, f32)); 10] = [
        ("gravity.x", |d, v| d.gravity.x = v),
        ("gravity.y", |d, v| d.gravity.y = v),
        ("gravity.z", |d, v| d.gravity.z = v),
        ("substep_rate", |d, v| d.substep_rate = v),
        ("time_scale", |d, v| d.time_scale = v),
        ("teleport_distance", |d, v| d.teleport_distance = v),
        ("teleport_angle", |d, v| d.teleport_angle = v),
        ("scale", |d, v| d.scale = v),
        ("sleep_speed", |d, v| d.sleep_speed = v),
        ("substep_rate", |d, v| d.substep_rate = v * 0.0 + if v.is_nan() { 29.0 } else { 10001.0 }),
    ];
    for (field, set) in fields {
        for (tag, v) in BAD_FLOATS {
            let mut def = d;
            set(&mut def, v);
            out.push((format!("{tag}:{{}}.{field}"), def, KDW_STATUS_INVALID_ARGUMENT));
        }
    }
    // Out of the documented ranges.
    let ranged: [(&str, kdw_engine_def); 18] = [
        ("huge", kdw_engine_def { substep_rate: 1e30, ..d }),
        ("range", kdw_engine_def { substep_rate: 0.0, ..d }),
        ("range", kdw_engine_def { max_substeps: 0, ..d }),
        ("range", kdw_engine_def { max_substeps: 1001, ..d }),
        ("range", kdw_engine_def { iterations: 0, ..d }),
        ("range", kdw_engine_def { iterations: 65, ..d }),
        ("huge", kdw_engine_def { time_scale: 1e30, ..d }),
        ("range", kdw_engine_def { time_scale: -1.0, ..d }),
        ("huge", kdw_engine_def { teleport_distance: -1e30, ..d }),
        ("huge", kdw_engine_def { teleport_angle: -1e30, ..d }),
        ("range", kdw_engine_def { teleport_mode: 2, ..d }),
        ("range", kdw_engine_def { teleport_mode: u32::MAX, ..d }),
        ("range", kdw_engine_def { scale: 0.0, ..d }),
        ("range", kdw_engine_def { scale: -1.0, ..d }),
        ("range", kdw_engine_def { scale: 1e-7, ..d }),
        ("huge", kdw_engine_def { scale: 1e7, ..d }),
        ("range", kdw_engine_def { sleep_speed: -1.0, ..d }),
        ("range", kdw_engine_def { lod: u32::MAX, ..d }),
    ];
    for (tag, def) in ranged {
        out.push((format!("{tag}:{{}}"), def, KDW_STATUS_INVALID_ARGUMENT));
    }
    out
}

fn chain_def_variants() -> Vec<(String, kdw_chain_def, kdw_status)> {
    let d = kdw_chain_def_default();
    let mut out = Vec::new();
    for size in [0u32, d.struct_size - 4, d.struct_size + 4, u32::MAX] {
        out.push(("struct_size:{}".into(), kdw_chain_def { struct_size: size, ..d }, KDW_STATUS_STRUCT_SIZE_MISMATCH));
    }
    let fields: [(&str, fn(&mut kdw_chain_def, f32)); 7] = [
        ("stiffness", |d, v| d.stiffness = v),
        ("damping", |d, v| d.damping = v),
        ("momentum_suppression", |d, v| d.momentum_suppression = v),
        ("mass", |d, v| d.mass = v),
        ("radius", |d, v| d.radius = v),
        ("gravity_scale", |d, v| d.gravity_scale = v),
        ("friction", |d, v| d.friction = v),
    ];
    for (field, set) in fields {
        for (tag, v) in BAD_FLOATS {
            let mut def = d;
            set(&mut def, v);
            out.push((format!("{tag}:{{}}.{field}"), def, KDW_STATUS_INVALID_ARGUMENT));
        }
    }
    let ranged: [(&str, kdw_chain_def); 17] = [
        ("huge", kdw_chain_def { stiffness: 1e30, ..d }),
        ("range", kdw_chain_def { stiffness: -0.1, ..d }),
        ("range", kdw_chain_def { stiffness: 1.01, ..d }),
        ("huge", kdw_chain_def { damping: 1e30, ..d }),
        ("range", kdw_chain_def { damping: -1.0, ..d }),
        ("huge", kdw_chain_def { momentum_suppression: 1e30, ..d }),
        ("range", kdw_chain_def { mass: 0.0, ..d }),
        ("huge", kdw_chain_def { mass: -1e30, ..d }),
        ("huge", kdw_chain_def { radius: -1e30, ..d }),
        ("huge", kdw_chain_def { gravity_scale: 1e30, ..d }),
        ("huge", kdw_chain_def { gravity_scale: -1e30, ..d }),
        ("range", kdw_chain_def { anchor: 2, ..d }),
        ("range", kdw_chain_def { anchor: u32::MAX, ..d }),
        ("range", kdw_chain_def { friction: -1.0, ..d }),
        ("range", kdw_chain_def { friction: 11.0, ..d }),
        ("huge", kdw_chain_def { friction: 1e30, ..d }),
        ("huge", kdw_chain_def { radius: 1e7, ..d }),
    ];
    for (tag, def) in ranged {
        out.push((format!("{tag}:{{}}"), def, KDW_STATUS_INVALID_ARGUMENT));
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn step_read(
    fx: &Fixture,
    dt: f32,
    cam: *const kdw_vec3,
    k: *const kdw_transform,
    anchors: *const kdw_transform,
    count: u32,
    capacity: u32,
    null_out: (bool, bool),
) -> (kdw_status, bool) {
    let mut rotations = vec![sentinel_quat(); 16];
    let mut written = SENTINEL_U32;
    let out = if null_out.0 { null_mut() } else { rotations.as_mut_ptr() };
    let w = if null_out.1 { null_mut() } else { &mut written as *mut u32 };
    let status = kdw_engine_step_and_read(fx.a, dt, cam, k, anchors, count, out, capacity, w);
    (status, written == SENTINEL_U32 && rotations.iter().all(|q| *q == sentinel_quat()))
}

fn stroke_camera_variants() -> Vec<(String, kdw_stroke_camera, kdw_status)> {
    let d = kdw_stroke_camera_default();
    let mut out = Vec::new();
    for size in [0u32, d.struct_size - 4, d.struct_size + 4] {
        out.push((
            "struct_size:{}".into(),
            kdw_stroke_camera { struct_size: size, ..d },
            KDW_STATUS_STRUCT_SIZE_MISMATCH,
        ));
    }
    let fields: [(&str, fn(&mut kdw_stroke_camera, f32)); 9] = [
        ("position.x", |c, v| c.position.x = v),
        ("position.y", |c, v| c.position.y = v),
        ("position.z", |c, v| c.position.z = v),
        ("vertical_fov", |c, v| c.vertical_fov = v),
        ("orthographic_half_height", |c, v| c.orthographic_half_height = v),
        ("viewport_width", |c, v| c.viewport_width = v),
        ("viewport_height", |c, v| c.viewport_height = v),
        ("rotation.w", |c, v| c.rotation.w = v),
        ("rotation.x", |c, v| c.rotation.x = v),
    ];
    for (field, set) in fields {
        for (tag, v) in BAD_FLOATS {
            let mut cam = d;
            if field == "orthographic_half_height" {
                // Only read by orthographic cameras (a perspective one ignores it: see the report).
                cam.projection = KDW_PROJECTION_ORTHOGRAPHIC;
            }
            set(&mut cam, v);
            out.push((format!("{tag}:{{}}.{field}"), cam, KDW_STATUS_INVALID_ARGUMENT));
        }
    }
    let ranged: [kdw_stroke_camera; 8] = [
        kdw_stroke_camera { vertical_fov: 0.0, ..d },
        kdw_stroke_camera { vertical_fov: 3.2, ..d },
        kdw_stroke_camera { viewport_width: 0.0, ..d },
        kdw_stroke_camera { viewport_height: -1e30, ..d },
        kdw_stroke_camera { projection: 2, ..d },
        kdw_stroke_camera { forward_axis: 2, ..d },
        kdw_stroke_camera { projection: KDW_PROJECTION_ORTHOGRAPHIC, orthographic_half_height: 0.0, ..d },
        kdw_stroke_camera { rotation: kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 0.0 }, ..d },
    ];
    for cam in ranged {
        out.push(("range:{}".into(), cam, KDW_STATUS_INVALID_ARGUMENT));
    }
    out
}

/// A valid `kdw_shape_from_stroke` call (a chain 3 m in front of the default camera), to break one
/// argument at a time.
#[derive(Clone)]
struct Stroke {
    camera: kdw_stroke_camera,
    joints: Vec<kdw_transform>,
    joint_count: u32,
    anchor: kdw_transform,
    view_reference: kdw_transform,
    pixels: Vec<kdw_vec2>,
    point_count: u32,
    capacity: u32,
    /// Which pointer to pass as NULL (in parameter order).
    null: Option<usize>,
}

impl Stroke {
    fn valid() -> Self {
        let joints = joints(N, 0.0)
            .into_iter()
            .map(|t| kdw_transform { position: vec3(t.position.x, t.position.y, -3.0), rotation: t.rotation })
            .collect();
        let anchor = kdw_transform { position: vec3(0.0, 0.0, -3.0), ..head() };
        Self {
            camera: kdw_stroke_camera_default(),
            joints,
            joint_count: N,
            anchor,
            view_reference: anchor,
            pixels: vec![kdw_vec2 { x: 960.0, y: 540.0 }, kdw_vec2 { x: 1010.0, y: 600.0 }],
            point_count: 2,
            capacity: N,
            null: None,
        }
    }

    fn call(&self) -> (kdw_status, bool) {
        let mut out = vec![sentinel_transform(); N as usize];
        let mut direction = vec3(SENTINEL_F, SENTINEL_F, SENTINEL_F);
        let pick = |i: usize| self.null != Some(i);
        let status = kdw_shape_from_stroke(
            if pick(0) { &self.camera } else { null() },
            if pick(1) { self.joints.as_ptr() } else { null() },
            self.joint_count,
            if pick(2) { &self.anchor } else { null() },
            if pick(3) { &self.view_reference } else { null() },
            if pick(4) { self.pixels.as_ptr() } else { null() },
            self.point_count,
            if pick(5) { out.as_mut_ptr() } else { null_mut() },
            self.capacity,
            if pick(6) { &mut direction } else { null_mut() },
        );
        let untouched =
            out.iter().all(|t| *t == sentinel_transform()) && direction == vec3(SENTINEL_F, SENTINEL_F, SENTINEL_F);
        (status, untouched)
    }
}

fn cases(fx: &Fixture) -> Vec<Case> {
    let mut c: Vec<Case> = Vec::new();
    let bad_chains = fx.bad_chain_ids();
    let bad_views = fx.bad_view_ids();
    let (nullp, badid, badarg, small) =
        (KDW_STATUS_NULL_POINTER, KDW_STATUS_INVALID_ID, KDW_STATUS_INVALID_ARGUMENT, KDW_STATUS_BUFFER_TOO_SMALL);

    // -- engine lifetime and settings
    c.push(case(
        "kdw_engine_create",
        "null:def",
        nullp,
        Box::new(|_| out(null_mut(), |o| kdw_engine_create(null(), o))),
    ));
    c.push(case(
        "kdw_engine_create",
        "null:out_engine",
        nullp,
        Box::new(|_| (kdw_engine_create(&kdw_engine_def_default(), null_mut()), true)),
    ));
    for (tag, def, expected) in engine_def_variants() {
        c.push(case(
            "kdw_engine_create",
            tag.replace("{}", "def"),
            expected,
            Box::new(move |_| {
                let mut engine = null_mut();
                let status = kdw_engine_create(&def, &mut engine);
                let untouched = engine.is_null();
                if !untouched {
                    kdw_engine_destroy(engine);
                }
                (status, untouched)
            }),
        ));
        c.push(case(
            "kdw_engine_set_def",
            tag.replace("{}", "def"),
            expected,
            Box::new(move |fx| (kdw_engine_set_def(fx.a, &def), true)),
        ));
    }
    c.push(case(
        "kdw_engine_get_def",
        "null:engine",
        nullp,
        Box::new(|_| out(sentinel_engine_def(), |o| kdw_engine_get_def(null(), o))),
    ));
    c.push(case(
        "kdw_engine_get_def",
        "null:out_def",
        nullp,
        Box::new(|fx| (kdw_engine_get_def(fx.a, null_mut()), true)),
    ));
    c.push(case(
        "kdw_engine_set_def",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_set_def(null_mut(), &kdw_engine_def_default()), true)),
    ));
    c.push(case("kdw_engine_set_def", "null:def", nullp, Box::new(|fx| (kdw_engine_set_def(fx.a, null()), true))));
    c.push(case(
        "kdw_engine_set_gravity",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_set_gravity(null_mut(), &vec3(0.0, -1.0, 0.0)), true)),
    ));
    c.push(case(
        "kdw_engine_set_gravity",
        "null:gravity",
        nullp,
        Box::new(|fx| (kdw_engine_set_gravity(fx.a, null()), true)),
    ));
    for (tag, g) in bad_vec3s() {
        c.push(case(
            "kdw_engine_set_gravity",
            format!("{tag}:gravity"),
            badarg,
            Box::new(move |fx| (kdw_engine_set_gravity(fx.a, &g), true)),
        ));
    }
    c.push(case(
        "kdw_engine_set_solver",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_set_solver(null_mut(), KDW_SOLVER_SCALAR), true)),
    ));
    for solver in [3u32, u32::MAX] {
        c.push(case(
            "kdw_engine_set_solver",
            format!("range:solver={solver}"),
            badarg,
            Box::new(move |fx| (kdw_engine_set_solver(fx.a, solver), true)),
        ));
    }
    c.push(case(
        "kdw_engine_get_solver",
        "null:engine",
        nullp,
        Box::new(|_| out(SENTINEL_U32, |o| kdw_engine_get_solver(null(), o))),
    ));
    c.push(case(
        "kdw_engine_get_solver",
        "null:out_solver",
        nullp,
        Box::new(|fx| (kdw_engine_get_solver(fx.a, null_mut()), true)),
    ));

    // -- step
    c.push(case(
        "kdw_engine_step",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_step(null_mut(), 0.1, &camera(), &head()), true)),
    ));
    c.push(case(
        "kdw_engine_step",
        "null:camera_position",
        nullp,
        Box::new(|fx| (kdw_engine_step(fx.a, 0.1, null(), &head()), true)),
    ));
    c.push(case(
        "kdw_engine_step",
        "null:view_reference",
        nullp,
        Box::new(|fx| (kdw_engine_step(fx.a, 0.1, &camera(), null()), true)),
    ));
    for (tag, dt) in BAD_FLOATS.into_iter().chain([("huge", -1e30f32), ("range", -1e-6), ("range", -0.0 - 1.0)]) {
        c.push(case(
            "kdw_engine_step",
            format!("{tag}:dt"),
            badarg,
            Box::new(move |fx| (kdw_engine_step(fx.a, dt, &camera(), &head()), true)),
        ));
    }
    for (tag, p) in bad_vec3s() {
        c.push(case(
            "kdw_engine_step",
            format!("{tag}:camera_position"),
            badarg,
            Box::new(move |fx| (kdw_engine_step(fx.a, 0.1, &p, &head()), true)),
        ));
    }
    for (tag, t) in bad_transforms() {
        c.push(case(
            "kdw_engine_step",
            format!("{tag}:view_reference"),
            badarg,
            Box::new(move |fx| (kdw_engine_step(fx.a, 0.1, &camera(), &t), true)),
        ));
    }

    // -- anchors
    c.push(case(
        "kdw_engine_set_anchors",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_set_anchors(null_mut(), [head(); 2].as_ptr(), 2), true)),
    ));
    c.push(case(
        "kdw_engine_set_anchors",
        "null:anchors",
        nullp,
        Box::new(|fx| (kdw_engine_set_anchors(fx.a, null(), fx.chain_total), true)),
    ));
    for count in [0u32, 1, 3, u32::MAX / 28] {
        c.push(case(
            "kdw_engine_set_anchors",
            format!("count:count={count}"),
            badarg,
            Box::new(move |fx| {
                let anchors = vec![head(); (count as usize).min(8)];
                if count as usize > anchors.len() {
                    // Never hand the library a count beyond the buffer: the engine has 2 chains, so a count
                    // of 3 is enough to be wrong; larger counts are covered by 3.
                    return (kdw_engine_set_anchors(fx.a, anchors.as_ptr(), 3.min(count)), true);
                }
                (kdw_engine_set_anchors(fx.a, anchors.as_ptr(), count), true)
            }),
        ));
    }
    for (tag, t) in bad_transforms() {
        for slot in 0..2 {
            c.push(case(
                "kdw_engine_set_anchors",
                format!("{tag}:anchors"),
                badarg,
                Box::new(move |fx| {
                    let mut anchors = [head(); 2];
                    anchors[slot] = t;
                    (kdw_engine_set_anchors(fx.a, anchors.as_ptr(), fx.chain_total), true)
                }),
            ));
        }
    }

    // -- engine queries
    let queries_u32: [(&'static str, extern "C" fn(*const kdw_engine, *mut u32) -> kdw_status); 3] = [
        ("kdw_engine_chain_count", kdw_engine_chain_count),
        ("kdw_engine_joint_count", kdw_engine_joint_count),
        ("kdw_engine_collider_count", kdw_engine_collider_count),
    ];
    for (name, f) in queries_u32 {
        c.push(case(name, "null:engine", nullp, Box::new(move |_| out(SENTINEL_U32, |o| f(null(), o)))));
        c.push(case(name, "null:out_count", nullp, Box::new(move |fx| (f(fx.a, null_mut()), true))));
    }
    c.push(case(
        "kdw_engine_state_hash",
        "null:engine",
        nullp,
        Box::new(|_| out(SENTINEL_U64, |o| kdw_engine_state_hash(null(), o))),
    ));
    c.push(case(
        "kdw_engine_state_hash",
        "null:out_hash",
        nullp,
        Box::new(|fx| (kdw_engine_state_hash(fx.a, null_mut()), true)),
    ));
    c.push(case(
        "kdw_engine_get_stats",
        "null:engine",
        nullp,
        Box::new(|_| {
            out(kdw_engine_stats { struct_size: SENTINEL_U32, ..Default::default() }, |o| {
                kdw_engine_get_stats(null(), o)
            })
        }),
    ));
    c.push(case(
        "kdw_engine_get_stats",
        "null:out_stats",
        nullp,
        Box::new(|fx| (kdw_engine_get_stats(fx.a, null_mut()), true)),
    ));
    c.push(case("kdw_engine_reset", "null:engine", nullp, Box::new(|_| (kdw_engine_reset(null_mut()), true))));

    // -- batched reads
    c.push(case(
        "kdw_engine_get_chain_ids",
        "null:engine",
        nullp,
        Box::new(|_| buffer(SENTINEL_U64, 4, |b, w| kdw_engine_get_chain_ids(null(), b, 4, w))),
    ));
    c.push(case(
        "kdw_engine_get_chain_ids",
        "null:out_ids",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |w| kdw_engine_get_chain_ids(fx.a, null_mut(), fx.chain_total, w))),
    ));
    c.push(case(
        "kdw_engine_get_chain_ids",
        "null:out_written",
        nullp,
        Box::new(|fx| buffer(SENTINEL_U64, 4, |b, _| kdw_engine_get_chain_ids(fx.a, b, 4, null_mut()))),
    ));
    for cap in [0u32, 1] {
        c.push(case(
            "kdw_engine_get_chain_ids",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| buffer(SENTINEL_U64, 4, |b, w| kdw_engine_get_chain_ids(fx.a, b, cap, w))),
        ));
    }
    c.push(case(
        "kdw_engine_read_world",
        "null:engine",
        nullp,
        Box::new(|_| buffer(sentinel_transform(), 16, |b, w| kdw_engine_read_world(null(), b, 16, w))),
    ));
    c.push(case(
        "kdw_engine_read_world",
        "null:out_transforms",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |w| kdw_engine_read_world(fx.a, null_mut(), fx.joint_total, w))),
    ));
    c.push(case(
        "kdw_engine_read_world",
        "null:out_written",
        nullp,
        Box::new(|fx| buffer(sentinel_transform(), 16, |b, _| kdw_engine_read_world(fx.a, b, 16, null_mut()))),
    ));
    c.push(case(
        "kdw_engine_read_local_rotations",
        "null:engine",
        nullp,
        Box::new(|_| buffer(sentinel_quat(), 16, |b, w| kdw_engine_read_local_rotations(null(), b, 16, w))),
    ));
    c.push(case(
        "kdw_engine_read_local_rotations",
        "null:out_rotations",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |w| kdw_engine_read_local_rotations(fx.a, null_mut(), fx.joint_total, w))),
    ));
    c.push(case(
        "kdw_engine_read_local_rotations",
        "null:out_written",
        nullp,
        Box::new(|fx| buffer(sentinel_quat(), 16, |b, _| kdw_engine_read_local_rotations(fx.a, b, 16, null_mut()))),
    ));
    for cap in [0u32, 1, 2 * N - 1] {
        c.push(case(
            "kdw_engine_read_world",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| buffer(sentinel_transform(), 16, |b, w| kdw_engine_read_world(fx.a, b, cap, w))),
        ));
        c.push(case(
            "kdw_engine_read_local_rotations",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| buffer(sentinel_quat(), 16, |b, w| kdw_engine_read_local_rotations(fx.a, b, cap, w))),
        ));
    }

    // -- chains
    let def = kdw_chain_def_default();
    c.push(case(
        "kdw_chain_create",
        "null:engine",
        nullp,
        Box::new(move |_| out(SENTINEL_U64, |o| kdw_chain_create(null_mut(), &def, joints(N, 0.0).as_ptr(), N, o))),
    ));
    c.push(case(
        "kdw_chain_create",
        "null:def",
        nullp,
        Box::new(|fx| out(SENTINEL_U64, |o| kdw_chain_create(fx.a, null(), joints(N, 0.0).as_ptr(), N, o))),
    ));
    c.push(case(
        "kdw_chain_create",
        "null:base_joints",
        nullp,
        Box::new(move |fx| out(SENTINEL_U64, |o| kdw_chain_create(fx.a, &def, null(), N, o))),
    ));
    c.push(case(
        "kdw_chain_create",
        "null:out_chain",
        nullp,
        Box::new(move |fx| (kdw_chain_create(fx.a, &def, joints(N, 0.0).as_ptr(), N, null_mut()), true)),
    ));
    for count in [0u32, 1] {
        c.push(case(
            "kdw_chain_create",
            format!("count:joint_count={count}"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| kdw_chain_create(fx.a, &def, joints(N, 0.0).as_ptr(), count, o))),
        ));
    }
    for (tag, j) in bad_joint_arrays(N) {
        c.push(case(
            "kdw_chain_create",
            format!("{tag}:base_joints"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| kdw_chain_create(fx.a, &def, j.as_ptr(), N, o))),
        ));
    }
    for (tag, d, expected) in chain_def_variants() {
        c.push(case(
            "kdw_chain_create",
            tag.replace("{}", "def"),
            expected,
            Box::new(move |fx| out(SENTINEL_U64, |o| kdw_chain_create(fx.a, &d, joints(N, 0.0).as_ptr(), N, o))),
        ));
        c.push(case(
            "kdw_chain_set_def",
            tag.replace("{}", "def"),
            expected,
            Box::new(move |fx| (kdw_chain_set_def(fx.a, fx.chain, &d), true)),
        ));
    }
    c.push(case(
        "kdw_chain_set_def",
        "null:engine",
        nullp,
        Box::new(move |fx| (kdw_chain_set_def(null_mut(), fx.chain, &def), true)),
    ));
    c.push(case(
        "kdw_chain_set_def",
        "null:def",
        nullp,
        Box::new(|fx| (kdw_chain_set_def(fx.a, fx.chain, null()), true)),
    ));
    c.push(case(
        "kdw_chain_get_def",
        "null:engine",
        nullp,
        Box::new(|fx| out(sentinel_chain_def(), |o| kdw_chain_get_def(null(), fx.chain, o))),
    ));
    c.push(case(
        "kdw_chain_get_def",
        "null:out_def",
        nullp,
        Box::new(|fx| (kdw_chain_get_def(fx.a, fx.chain, null_mut()), true)),
    ));
    c.push(case(
        "kdw_chain_destroy",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_chain_destroy(null_mut(), fx.chain), true)),
    ));
    c.push(case("kdw_chain_reset", "null:engine", nullp, Box::new(|fx| (kdw_chain_reset(null_mut(), fx.chain), true))));
    c.push(case(
        "kdw_chain_set_base_shape",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_chain_set_base_shape(null_mut(), fx.chain, joints(N, 0.5).as_ptr(), N), true)),
    ));
    c.push(case(
        "kdw_chain_set_base_shape",
        "null:joints",
        nullp,
        Box::new(|fx| (kdw_chain_set_base_shape(fx.a, fx.chain, null(), N), true)),
    ));
    for count in [0u32, 1, N - 1] {
        c.push(case(
            "kdw_chain_set_base_shape",
            format!("count:joint_count={count}"),
            badarg,
            Box::new(move |fx| (kdw_chain_set_base_shape(fx.a, fx.chain, joints(N, 0.5).as_ptr(), count), true)),
        ));
    }
    c.push(case(
        "kdw_chain_set_base_shape",
        "count:joint_count=N+1",
        badarg,
        Box::new(|fx| (kdw_chain_set_base_shape(fx.a, fx.chain, joints(N + 1, 0.5).as_ptr(), N + 1), true)),
    ));
    for (tag, j) in bad_joint_arrays(N) {
        c.push(case(
            "kdw_chain_set_base_shape",
            format!("{tag}:joints"),
            badarg,
            Box::new(move |fx| (kdw_chain_set_base_shape(fx.a, fx.chain, j.as_ptr(), N), true)),
        ));
    }
    let chain_u32: [(&'static str, &'static str, extern "C" fn(*const kdw_engine, u64, *mut u32) -> kdw_status); 5] = [
        ("kdw_chain_is_valid", "out_valid", kdw_chain_is_valid),
        ("kdw_chain_joint_count", "out_count", kdw_chain_joint_count),
        ("kdw_chain_view_shape_count", "out_count", kdw_chain_view_shape_count),
        ("kdw_chain_is_enabled", "out_enabled", kdw_chain_is_enabled),
        ("kdw_chain_is_asleep", "out_asleep", kdw_chain_is_asleep),
    ];
    for (name, out_name, f) in chain_u32 {
        c.push(case(name, "null:engine", nullp, Box::new(move |fx| out(SENTINEL_U32, |o| f(null(), fx.chain, o)))));
        c.push(case(
            name,
            format!("null:{out_name}"),
            nullp,
            Box::new(move |fx| (f(fx.a, fx.chain, null_mut()), true)),
        ));
    }
    c.push(case(
        "kdw_chain_kinetic_energy",
        "null:engine",
        nullp,
        Box::new(|fx| out(SENTINEL_F, |o| kdw_chain_kinetic_energy(null(), fx.chain, o))),
    ));
    c.push(case(
        "kdw_chain_kinetic_energy",
        "null:out_energy",
        nullp,
        Box::new(|fx| (kdw_chain_kinetic_energy(fx.a, fx.chain, null_mut()), true)),
    ));
    let chain_reads: [(
        &'static str,
        extern "C" fn(*const kdw_engine, u64, *mut kdw_transform, u32, *mut u32) -> kdw_status,
    ); 2] = [("kdw_chain_read_world", kdw_chain_read_world), ("kdw_chain_read_rest_shape", kdw_chain_read_rest_shape)];
    for (name, f) in chain_reads {
        c.push(case(
            name,
            "null:engine",
            nullp,
            Box::new(move |fx| buffer(sentinel_transform(), 8, |b, w| f(null(), fx.chain, b, 8, w))),
        ));
        c.push(case(
            name,
            "null:out_transforms",
            nullp,
            Box::new(move |fx| out(SENTINEL_U32, |w| f(fx.a, fx.chain, null_mut(), N, w))),
        ));
        c.push(case(
            name,
            "null:out_written",
            nullp,
            Box::new(move |fx| buffer(sentinel_transform(), 8, |b, _| f(fx.a, fx.chain, b, 8, null_mut()))),
        ));
        for cap in [0u32, 1, N - 1] {
            c.push(case(
                name,
                format!("count:capacity={cap}"),
                small,
                Box::new(move |fx| buffer(sentinel_transform(), 8, |b, w| f(fx.a, fx.chain, b, cap, w))),
            ));
        }
        for (tag, id) in bad_chains {
            c.push(case(
                name,
                format!("{tag}:chain"),
                badid,
                Box::new(move |fx| buffer(sentinel_transform(), 8, |b, w| f(fx.a, id, b, 8, w))),
            ));
        }
    }
    // Every function taking a chain id, with each bad id (is_valid answers 0 instead: see below).
    for (tag, id) in bad_chains {
        let t = format!("{tag}:chain");
        c.push(case("kdw_chain_destroy", t.clone(), badid, Box::new(move |fx| (kdw_chain_destroy(fx.a, id), true))));
        c.push(case("kdw_chain_reset", t.clone(), badid, Box::new(move |fx| (kdw_chain_reset(fx.a, id), true))));
        c.push(case(
            "kdw_chain_set_def",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_chain_set_def(fx.a, id, &def), true)),
        ));
        c.push(case(
            "kdw_chain_get_def",
            t.clone(),
            badid,
            Box::new(move |fx| out(sentinel_chain_def(), |o| kdw_chain_get_def(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_set_base_shape",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_chain_set_base_shape(fx.a, id, joints(N, 0.5).as_ptr(), N), true)),
        ));
        c.push(case(
            "kdw_chain_joint_count",
            t.clone(),
            badid,
            Box::new(move |fx| out(SENTINEL_U32, |o| kdw_chain_joint_count(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_view_shape_count",
            t.clone(),
            badid,
            Box::new(move |fx| out(SENTINEL_U32, |o| kdw_chain_view_shape_count(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_is_enabled",
            t.clone(),
            badid,
            Box::new(move |fx| out(SENTINEL_U32, |o| kdw_chain_is_enabled(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_is_asleep",
            t.clone(),
            badid,
            Box::new(move |fx| out(SENTINEL_U32, |o| kdw_chain_is_asleep(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_set_enabled",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_chain_set_enabled(fx.a, id, 0), true)),
        ));
        c.push(case(
            "kdw_chain_kinetic_energy",
            t.clone(),
            badid,
            Box::new(move |fx| out(SENTINEL_F, |o| kdw_chain_kinetic_energy(fx.a, id, o))),
        ));
        c.push(case(
            "kdw_chain_add_view_shape",
            t.clone(),
            badid,
            Box::new(move |fx| {
                out(SENTINEL_U64, |o| {
                    kdw_chain_add_view_shape(fx.a, id, &vec3(0.0, 0.0, 1.0), joints(N, 1.0).as_ptr(), N, 1.0, o)
                })
            }),
        ));
    }

    // -- blend weights (chain has 1 view shape: capacity >= 2)
    c.push(case(
        "kdw_chain_read_weights",
        "null:engine",
        nullp,
        Box::new(|fx| buffer(SENTINEL_F, 4, |b, w| kdw_chain_read_weights(null(), fx.chain, b, 4, w))),
    ));
    c.push(case(
        "kdw_chain_read_weights",
        "null:out_weights",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |w| kdw_chain_read_weights(fx.a, fx.chain, null_mut(), 4, w))),
    ));
    c.push(case(
        "kdw_chain_read_weights",
        "null:out_written",
        nullp,
        Box::new(|fx| buffer(SENTINEL_F, 4, |b, _| kdw_chain_read_weights(fx.a, fx.chain, b, 4, null_mut()))),
    ));
    for cap in [0u32, 1] {
        c.push(case(
            "kdw_chain_read_weights",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| buffer(SENTINEL_F, 4, |b, w| kdw_chain_read_weights(fx.a, fx.chain, b, cap, w))),
        ));
    }
    for (tag, id) in bad_chains {
        c.push(case(
            "kdw_chain_read_weights",
            format!("{tag}:chain"),
            badid,
            Box::new(move |fx| buffer(SENTINEL_F, 4, |b, w| kdw_chain_read_weights(fx.a, id, b, 4, w))),
        ));
    }

    // -- view shapes
    let dir = vec3(0.0, 0.0, 1.0);
    let add = |fx: &Fixture, d: &kdw_vec3, j: *const kdw_transform, n: u32, k: f32, o: *mut u64| {
        kdw_chain_add_view_shape(fx.a, fx.chain, d, j, n, k, o)
    };
    c.push(case(
        "kdw_chain_add_view_shape",
        "null:engine",
        nullp,
        Box::new(move |fx| {
            out(SENTINEL_U64, |o| {
                kdw_chain_add_view_shape(null_mut(), fx.chain, &dir, joints(N, 1.0).as_ptr(), N, 1.0, o)
            })
        }),
    ));
    c.push(case(
        "kdw_chain_add_view_shape",
        "null:direction",
        nullp,
        Box::new(move |fx| {
            out(SENTINEL_U64, |o| kdw_chain_add_view_shape(fx.a, fx.chain, null(), joints(N, 1.0).as_ptr(), N, 1.0, o))
        }),
    ));
    c.push(case(
        "kdw_chain_add_view_shape",
        "null:joints",
        nullp,
        Box::new(move |fx| out(SENTINEL_U64, |o| add(fx, &dir, null(), N, 1.0, o))),
    ));
    c.push(case(
        "kdw_chain_add_view_shape",
        "null:out_view_shape",
        nullp,
        Box::new(move |fx| (add(fx, &dir, joints(N, 1.0).as_ptr(), N, 1.0, null_mut()), true)),
    ));
    for count in [0u32, 1, N - 1] {
        c.push(case(
            "kdw_chain_add_view_shape",
            format!("count:joint_count={count}"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| add(fx, &dir, joints(N, 1.0).as_ptr(), count, 1.0, o))),
        ));
    }
    for (tag, j) in bad_joint_arrays(N) {
        c.push(case(
            "kdw_chain_add_view_shape",
            format!("{tag}:joints"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| add(fx, &dir, j.as_ptr(), N, 1.0, o))),
        ));
    }
    let mut bad_directions = bad_vec3s();
    bad_directions.push(("zero".into(), vec3(0.0, 0.0, 0.0)));
    bad_directions.push(("subnormal-zero".into(), vec3(-0.0, 0.0, -0.0)));
    for (tag, d) in bad_directions {
        c.push(case(
            "kdw_chain_add_view_shape",
            format!("{tag}:direction"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| add(fx, &d, joints(N, 1.0).as_ptr(), N, 1.0, o))),
        ));
        c.push(case(
            "kdw_view_shape_set_direction",
            format!("{tag}:direction"),
            badarg,
            Box::new(move |fx| (kdw_view_shape_set_direction(fx.a, fx.view, &d), true)),
        ));
    }
    for (tag, k) in BAD_FLOATS.into_iter().chain([("huge", -1e30f32), ("range", 0.0), ("range", -1.0)]) {
        c.push(case(
            "kdw_chain_add_view_shape",
            format!("{tag}:influence"),
            badarg,
            Box::new(move |fx| out(SENTINEL_U64, |o| add(fx, &dir, joints(N, 1.0).as_ptr(), N, k, o))),
        ));
        c.push(case(
            "kdw_view_shape_set_influence",
            format!("{tag}:influence"),
            badarg,
            Box::new(move |fx| (kdw_view_shape_set_influence(fx.a, fx.view, k), true)),
        ));
    }
    c.push(case(
        "kdw_view_shape_set_influence",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_view_shape_set_influence(null_mut(), fx.view, 1.0), true)),
    ));
    c.push(case(
        "kdw_view_shape_set_direction",
        "null:engine",
        nullp,
        Box::new(move |fx| (kdw_view_shape_set_direction(null_mut(), fx.view, &dir), true)),
    ));
    c.push(case(
        "kdw_view_shape_set_direction",
        "null:direction",
        nullp,
        Box::new(|fx| (kdw_view_shape_set_direction(fx.a, fx.view, null()), true)),
    ));
    c.push(case(
        "kdw_view_shape_set_joints",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_view_shape_set_joints(null_mut(), fx.view, joints(N, 1.0).as_ptr(), N), true)),
    ));
    c.push(case(
        "kdw_view_shape_set_joints",
        "null:joints",
        nullp,
        Box::new(|fx| (kdw_view_shape_set_joints(fx.a, fx.view, null(), N), true)),
    ));
    for count in [0u32, 1, N - 1] {
        c.push(case(
            "kdw_view_shape_set_joints",
            format!("count:joint_count={count}"),
            badarg,
            Box::new(move |fx| (kdw_view_shape_set_joints(fx.a, fx.view, joints(N, 1.0).as_ptr(), count), true)),
        ));
    }
    for (tag, j) in bad_joint_arrays(N) {
        c.push(case(
            "kdw_view_shape_set_joints",
            format!("{tag}:joints"),
            badarg,
            Box::new(move |fx| (kdw_view_shape_set_joints(fx.a, fx.view, j.as_ptr(), N), true)),
        ));
    }
    c.push(case(
        "kdw_view_shape_is_valid",
        "null:engine",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |o| kdw_view_shape_is_valid(null(), fx.view, o))),
    ));
    c.push(case(
        "kdw_view_shape_is_valid",
        "null:out_valid",
        nullp,
        Box::new(|fx| (kdw_view_shape_is_valid(fx.a, fx.view, null_mut()), true)),
    ));
    c.push(case(
        "kdw_view_shape_remove",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_view_shape_remove(null_mut(), fx.view), true)),
    ));
    for (tag, id) in bad_views {
        let t = format!("{tag}:view_shape");
        c.push(case(
            "kdw_view_shape_remove",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_view_shape_remove(fx.a, id), true)),
        ));
        c.push(case(
            "kdw_view_shape_set_influence",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_view_shape_set_influence(fx.a, id, 1.0), true)),
        ));
        c.push(case(
            "kdw_view_shape_set_direction",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_view_shape_set_direction(fx.a, id, &dir), true)),
        ));
        c.push(case(
            "kdw_view_shape_set_joints",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_view_shape_set_joints(fx.a, id, joints(N, 1.0).as_ptr(), N), true)),
        ));
    }

    collider_and_teleport_cases(fx, &mut c);
    c.push(case(
        "kdw_chain_set_enabled",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_chain_set_enabled(null_mut(), fx.chain, 0), true)),
    ));
    engines_step_cases(&mut c);

    // -- one-call frame
    let anchors2 = [head(); 2];
    c.push(case(
        "kdw_engine_step_and_read",
        "null:engine",
        nullp,
        Box::new(move |_| {
            buffer(sentinel_quat(), 16, |b, w| {
                kdw_engine_step_and_read(null_mut(), 0.1, &camera(), &head(), anchors2.as_ptr(), 2, b, 16, w)
            })
        }),
    ));
    c.push(case(
        "kdw_engine_step_and_read",
        "null:camera_position",
        nullp,
        Box::new(move |fx| step_read(fx, 0.1, null(), &head(), anchors2.as_ptr(), 2, 16, (false, false))),
    ));
    c.push(case(
        "kdw_engine_step_and_read",
        "null:view_reference",
        nullp,
        Box::new(move |fx| step_read(fx, 0.1, &camera(), null(), anchors2.as_ptr(), 2, 16, (false, false))),
    ));
    c.push(case(
        "kdw_engine_step_and_read",
        "null:anchors",
        nullp,
        Box::new(move |fx| step_read(fx, 0.1, &camera(), &head(), null(), 2, 16, (false, false))),
    ));
    c.push(case(
        "kdw_engine_step_and_read",
        "null:out_local_rotations",
        nullp,
        Box::new(move |fx| step_read(fx, 0.1, &camera(), &head(), anchors2.as_ptr(), 2, 16, (true, false))),
    ));
    c.push(case(
        "kdw_engine_step_and_read",
        "null:out_written",
        nullp,
        Box::new(move |fx| step_read(fx, 0.1, &camera(), &head(), anchors2.as_ptr(), 2, 16, (false, true))),
    ));
    for (tag, dt) in BAD_FLOATS.into_iter().chain([("huge", -1e30f32), ("range", -1e-6)]) {
        c.push(case(
            "kdw_engine_step_and_read",
            format!("{tag}:dt"),
            badarg,
            Box::new(move |fx| step_read(fx, dt, &camera(), &head(), anchors2.as_ptr(), 2, 16, (false, false))),
        ));
    }
    for (tag, p) in bad_vec3s() {
        c.push(case(
            "kdw_engine_step_and_read",
            format!("{tag}:camera_position"),
            badarg,
            Box::new(move |fx| step_read(fx, 0.1, &p, &head(), anchors2.as_ptr(), 2, 16, (false, false))),
        ));
    }
    for (tag, t) in bad_transforms() {
        c.push(case(
            "kdw_engine_step_and_read",
            format!("{tag}:view_reference"),
            badarg,
            Box::new(move |fx| step_read(fx, 0.1, &camera(), &t, anchors2.as_ptr(), 2, 16, (false, false))),
        ));
        c.push(case(
            "kdw_engine_step_and_read",
            format!("{tag}:anchors"),
            badarg,
            Box::new(move |fx| {
                let anchors = [head(), t];
                step_read(fx, 0.1, &camera(), &head(), anchors.as_ptr(), 2, 16, (false, false))
            }),
        ));
    }
    for count in [0u32, 1] {
        c.push(case(
            "kdw_engine_step_and_read",
            format!("count:anchor_count={count}"),
            badarg,
            Box::new(move |fx| step_read(fx, 0.1, &camera(), &head(), anchors2.as_ptr(), count, 16, (false, false))),
        ));
    }
    c.push(case(
        "kdw_engine_step_and_read",
        "count:anchor_count=3",
        badarg,
        Box::new(|fx| {
            let anchors = [head(); 3];
            step_read(fx, 0.1, &camera(), &head(), anchors.as_ptr(), 3, 16, (false, false))
        }),
    ));
    for cap in [0u32, 2 * N - 1] {
        c.push(case(
            "kdw_engine_step_and_read",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| step_read(fx, 0.1, &camera(), &head(), anchors2.as_ptr(), 2, cap, (false, false))),
        ));
    }

    // -- sketch tool (no engine involved)
    c.push(case(
        "kdw_stroke_camera_project",
        "null:camera",
        nullp,
        Box::new(|_| {
            out(kdw_vec2 { x: SENTINEL_F, y: SENTINEL_F }, |o| {
                kdw_stroke_camera_project(null(), &vec3(0.0, 0.0, -3.0), o)
            })
        }),
    ));
    c.push(case(
        "kdw_stroke_camera_project",
        "null:point",
        nullp,
        Box::new(|_| {
            out(kdw_vec2 { x: SENTINEL_F, y: SENTINEL_F }, |o| {
                kdw_stroke_camera_project(&kdw_stroke_camera_default(), null(), o)
            })
        }),
    ));
    c.push(case(
        "kdw_stroke_camera_project",
        "null:out_pixel",
        nullp,
        Box::new(|_| {
            (kdw_stroke_camera_project(&kdw_stroke_camera_default(), &vec3(0.0, 0.0, -3.0), null_mut()), true)
        }),
    ));
    for (tag, p) in bad_vec3s().into_iter().chain([("behind".to_string(), vec3(0.0, 0.0, 3.0))]) {
        c.push(case(
            "kdw_stroke_camera_project",
            format!("{tag}:point"),
            badarg,
            Box::new(move |_| {
                out(kdw_vec2 { x: SENTINEL_F, y: SENTINEL_F }, |o| {
                    kdw_stroke_camera_project(&kdw_stroke_camera_default(), &p, o)
                })
            }),
        ));
    }
    for (tag, cam, expected) in stroke_camera_variants() {
        c.push(case(
            "kdw_stroke_camera_project",
            tag.replace("{}", "camera"),
            expected,
            Box::new(move |_| {
                out(kdw_vec2 { x: SENTINEL_F, y: SENTINEL_F }, |o| {
                    kdw_stroke_camera_project(&cam, &vec3(0.0, 0.0, -3.0), o)
                })
            }),
        ));
        c.push(case(
            "kdw_shape_from_stroke",
            tag.replace("{}", "camera"),
            expected,
            Box::new(move |_| Stroke { camera: cam, ..Stroke::valid() }.call()),
        ));
    }
    type Edit = fn(&mut Stroke);
    let stroke_cases: [(&str, kdw_status, Edit); 13] = [
        ("null:camera", nullp, |s| s.null = Some(0)),
        ("null:current_world_joints", nullp, |s| s.null = Some(1)),
        ("null:anchor_world", nullp, |s| s.null = Some(2)),
        ("null:view_reference_world", nullp, |s| s.null = Some(3)),
        ("null:stroke_pixels", nullp, |s| s.null = Some(4)),
        ("null:out_anchor_joints", nullp, |s| s.null = Some(5)),
        ("null:out_view_direction", nullp, |s| s.null = Some(6)),
        ("count:joint_count=0", badarg, |s| s.joint_count = 0),
        ("count:joint_count=1", badarg, |s| s.joint_count = 1),
        ("count:point_count=0", badarg, |s| s.point_count = 0),
        ("count:point_count=1", badarg, |s| s.point_count = 1),
        ("count:capacity=0", small, |s| s.capacity = 0),
        ("count:capacity=N-1", small, |s| s.capacity = N - 1),
    ];
    for (tag, expected, edit) in stroke_cases {
        c.push(case(
            "kdw_shape_from_stroke",
            tag,
            expected,
            Box::new(move |_| {
                let mut s = Stroke::valid();
                edit(&mut s);
                s.call()
            }),
        ));
    }
    for (tag, j) in bad_joint_arrays(N) {
        c.push(case(
            "kdw_shape_from_stroke",
            format!("{tag}:current_world_joints"),
            badarg,
            Box::new(move |_| {
                let mut s = Stroke::valid();
                for (dst, src) in s.joints.iter_mut().zip(&j) {
                    *dst = kdw_transform {
                        position: vec3(src.position.x, src.position.y, src.position.z - 3.0),
                        rotation: src.rotation,
                    };
                }
                s.call()
            }),
        ));
    }
    for (tag, t) in bad_transforms() {
        c.push(case(
            "kdw_shape_from_stroke",
            format!("{tag}:anchor_world"),
            badarg,
            Box::new(move |_| Stroke { anchor: t, ..Stroke::valid() }.call()),
        ));
        c.push(case(
            "kdw_shape_from_stroke",
            format!("{tag}:view_reference_world"),
            badarg,
            Box::new(move |_| Stroke { view_reference: t, ..Stroke::valid() }.call()),
        ));
    }
    for (tag, v) in BAD_FLOATS {
        for k in 0..2 {
            c.push(case(
                "kdw_shape_from_stroke",
                format!("{tag}:stroke_pixels"),
                badarg,
                Box::new(move |_| {
                    let mut s = Stroke::valid();
                    if k == 0 {
                        s.pixels[1].x = v;
                    } else {
                        s.pixels[0].y = v;
                    }
                    s.call()
                }),
            ));
        }
    }
    c.push(case(
        "kdw_shape_from_stroke",
        "duplicate:stroke_pixels",
        badarg,
        Box::new(|_| {
            let mut s = Stroke::valid();
            s.pixels[1] = s.pixels[0];
            s.call()
        }),
    ));
    c
}

/// Every way a collider def can be wrong, each with the status it must be rejected with.
fn collider_def_variants() -> Vec<(String, kdw_collider_def, kdw_status)> {
    let sphere = collider_def(KDW_COLLIDER_SPHERE, 0.1, 0.0);
    let capsule = collider_def(KDW_COLLIDER_CAPSULE, 0.05, 0.1);
    let mut out = Vec::new();
    for size in [0u32, sphere.struct_size - 4, sphere.struct_size + 4, u32::MAX] {
        out.push((
            "struct_size:{}".into(),
            kdw_collider_def { struct_size: size, ..sphere },
            KDW_STATUS_STRUCT_SIZE_MISMATCH,
        ));
    }
    // Floats only a capsule reads are broken on a capsule (a sphere ignores `half_height`: see the report).
    let fields: [(&str, kdw_collider_def, fn(&mut kdw_collider_def, f32)); 11] = [
        ("radius", sphere, |d, v| d.radius = v),
        ("radius", capsule, |d, v| d.radius = v),
        ("half_height", capsule, |d, v| d.half_height = v),
        ("transform.position.x", sphere, |d, v| d.transform.position.x = v),
        ("transform.position.y", sphere, |d, v| d.transform.position.y = v),
        ("transform.position.z", sphere, |d, v| d.transform.position.z = v),
        ("transform.rotation.x", sphere, |d, v| d.transform.rotation.x = v),
        ("transform.rotation.y", sphere, |d, v| d.transform.rotation.y = v),
        ("transform.rotation.z", sphere, |d, v| d.transform.rotation.z = v),
        ("transform.rotation.w", sphere, |d, v| d.transform.rotation.w = v),
        ("transform.rotation.w", capsule, |d, v| d.transform.rotation.w = v),
    ];
    for (field, base, set) in fields {
        for (tag, v) in BAD_FLOATS {
            let mut def = base;
            set(&mut def, v);
            out.push((format!("{tag}:{{}}.{field}"), def, KDW_STATUS_INVALID_ARGUMENT));
        }
    }
    let null_rotation = kdw_quat { x: 0.0, y: 0.0, z: 0.0, w: 0.0 };
    let far = kdw_transform { position: vec3(0.0, 1e30, 0.0), ..head() };
    let ranged: [(&str, kdw_collider_def); 21] = [
        ("range", kdw_collider_def { radius: -0.01, ..sphere }),
        ("range", kdw_collider_def { radius: -0.01, ..capsule }),
        ("range", kdw_collider_def { half_height: -0.01, ..capsule }),
        ("huge", kdw_collider_def { radius: 1e7, ..sphere }),
        ("huge", kdw_collider_def { half_height: 1e30, ..capsule }),
        ("degenerate", collider_def(KDW_COLLIDER_CAPSULE, 0.0, 0.0)),
        ("degenerate", collider_def(KDW_COLLIDER_INSIDE_CAPSULE, 0.0, 0.0)),
        ("inside-zero", collider_def(KDW_COLLIDER_INSIDE_SPHERE, 0.0, 0.0)),
        ("inside-zero", collider_def(KDW_COLLIDER_INSIDE_CAPSULE, 0.0, 0.1)),
        ("range", collider_def(KDW_COLLIDER_INSIDE_SPHERE, -1.0, 0.0)),
        ("shape", collider_def(KDW_COLLIDER_INSIDE_CAPSULE + 1, 0.1, 0.0)),
        ("shape", collider_def(u32::MAX, 0.1, 0.0)),
        (
            "nullquat",
            kdw_collider_def { transform: kdw_transform { rotation: null_rotation, ..sphere.transform }, ..sphere },
        ),
        ("nullquat", kdw_collider_def { transform: kdw_transform { rotation: null_rotation, ..head() }, ..capsule }),
        ("huge", kdw_collider_def { transform: far, ..sphere }),
        ("huge", kdw_collider_def { transform: far, ..collider_def(KDW_COLLIDER_PLANE, 0.0, 0.0) }),
        (
            "range",
            kdw_collider_def { transform: kdw_transform { position: vec3(-1.1e9, 0.0, 0.0), ..head() }, ..sphere },
        ),
        (
            "nan",
            kdw_collider_def {
                transform: kdw_transform { position: vec3(f32::NAN, 0.0, 0.0), ..head() },
                ..collider_def(KDW_COLLIDER_PLANE, 0.0, 0.0)
            },
        ),
        // Fields a shape does not use are ignored, but must still be valid.
        ("unused", collider_def(KDW_COLLIDER_SPHERE, 0.1, f32::NAN)),
        ("unused", collider_def(KDW_COLLIDER_INSIDE_SPHERE, 0.1, -1.0)),
        ("unused", collider_def(KDW_COLLIDER_PLANE, f32::INFINITY, 0.0)),
    ];
    for (tag, def) in ranged {
        out.push((format!("{tag}:{{}}"), def, KDW_STATUS_INVALID_ARGUMENT));
    }
    out
}

/// Colliders, per-joint radii and teleports: every pointer NULL, every id bad, counts wrong, values out of range.
fn collider_and_teleport_cases(fx: &Fixture, c: &mut Vec<Case>) {
    let (nullp, badid, badarg, small) =
        (KDW_STATUS_NULL_POINTER, KDW_STATUS_INVALID_ID, KDW_STATUS_INVALID_ARGUMENT, KDW_STATUS_BUFFER_TOO_SMALL);
    let sphere = collider_def(KDW_COLLIDER_SPHERE, 0.1, 0.0);

    // -- create
    c.push(case(
        "kdw_collider_create",
        "null:engine",
        nullp,
        Box::new(move |_| out(SENTINEL_U64, |o| kdw_collider_create(null_mut(), &sphere, o))),
    ));
    c.push(case(
        "kdw_collider_create",
        "null:def",
        nullp,
        Box::new(|fx| out(SENTINEL_U64, |o| kdw_collider_create(fx.a, null(), o))),
    ));
    c.push(case(
        "kdw_collider_create",
        "null:out_collider",
        nullp,
        Box::new(move |fx| (kdw_collider_create(fx.a, &sphere, null_mut()), true)),
    ));
    for (tag, def, expected) in collider_def_variants() {
        c.push(case(
            "kdw_collider_create",
            tag.replace("{}", "def"),
            expected,
            Box::new(move |fx| out(SENTINEL_U64, |o| kdw_collider_create(fx.a, &def, o))),
        ));
    }

    // -- ids
    c.push(case(
        "kdw_collider_destroy",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_collider_destroy(null_mut(), fx.collider), true)),
    ));
    c.push(case(
        "kdw_collider_is_valid",
        "null:engine",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |o| kdw_collider_is_valid(null(), fx.collider, o))),
    ));
    c.push(case(
        "kdw_collider_is_valid",
        "null:out_valid",
        nullp,
        Box::new(|fx| (kdw_collider_is_valid(fx.a, fx.collider, null_mut()), true)),
    ));
    c.push(case(
        "kdw_collider_set_layers",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_collider_set_layers(null_mut(), fx.collider, 2), true)),
    ));
    c.push(case(
        "kdw_collider_set_size",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_collider_set_size(null_mut(), fx.collider, 0.1, 0.0), true)),
    ));
    for (tag, v) in BAD_FLOATS.into_iter().chain([("range", -0.1), ("huge", 1e30)]) {
        c.push(case(
            "kdw_collider_set_size",
            format!("{tag}:radius"),
            badarg,
            Box::new(move |fx| (kdw_collider_set_size(fx.a, fx.collider, v, 0.0), true)),
        ));
        // The fixture's first collider is a sphere: its half height is unused but still checked.
        c.push(case(
            "kdw_collider_set_size",
            format!("{tag}:half_height"),
            badarg,
            Box::new(move |fx| (kdw_collider_set_size(fx.a, fx.collider, 0.1, v), true)),
        ));
    }
    for (tag, id) in fx.bad_collider_ids() {
        let t = format!("{tag}:collider");
        c.push(case(
            "kdw_collider_set_size",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_collider_set_size(fx.a, id, 0.1, 0.0), true)),
        ));
        c.push(case(
            "kdw_collider_destroy",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_collider_destroy(fx.a, id), true)),
        ));
        c.push(case(
            "kdw_collider_set_layers",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_collider_set_layers(fx.a, id, 2), true)),
        ));
    }

    // -- batched collider poses (the fixture's engine `a` has 2 colliders)
    c.push(case(
        "kdw_engine_set_collider_transforms",
        "null:engine",
        nullp,
        Box::new(|_| (kdw_engine_set_collider_transforms(null_mut(), collider_poses().as_ptr(), 2), true)),
    ));
    c.push(case(
        "kdw_engine_set_collider_transforms",
        "null:transforms",
        nullp,
        Box::new(|fx| (kdw_engine_set_collider_transforms(fx.a, null(), fx.collider_total), true)),
    ));
    for count in [0u32, 1, 3] {
        c.push(case(
            "kdw_engine_set_collider_transforms",
            format!("count:count={count}"),
            badarg,
            Box::new(move |fx| {
                let poses = [collider_poses()[0]; 3];
                (kdw_engine_set_collider_transforms(fx.a, poses.as_ptr(), count), true)
            }),
        ));
    }
    c.push(case(
        "kdw_engine_set_collider_transforms",
        "count:count=0,NULL",
        badarg,
        Box::new(|fx| (kdw_engine_set_collider_transforms(fx.a, null(), 0), true)),
    ));
    let mut bad_poses = bad_transforms();
    bad_poses.push(("huge".into(), kdw_transform { position: vec3(1e30, 0.0, 0.0), ..head() }));
    bad_poses.push(("range".into(), kdw_transform { position: vec3(0.0, 0.0, -2e9), ..head() }));
    for (tag, t) in bad_poses {
        for slot in 0..2 {
            c.push(case(
                "kdw_engine_set_collider_transforms",
                format!("{tag}:transforms"),
                badarg,
                Box::new(move |fx| {
                    let mut poses = collider_poses();
                    poses[slot] = t;
                    (kdw_engine_set_collider_transforms(fx.a, poses.as_ptr(), fx.collider_total), true)
                }),
            ));
        }
    }

    // -- collider ids read-back
    c.push(case(
        "kdw_engine_get_collider_ids",
        "null:engine",
        nullp,
        Box::new(|_| buffer(SENTINEL_U64, 4, |b, w| kdw_engine_get_collider_ids(null(), b, 4, w))),
    ));
    c.push(case(
        "kdw_engine_get_collider_ids",
        "null:out_ids",
        nullp,
        Box::new(|fx| out(SENTINEL_U32, |w| kdw_engine_get_collider_ids(fx.a, null_mut(), fx.collider_total, w))),
    ));
    c.push(case(
        "kdw_engine_get_collider_ids",
        "null:out_written",
        nullp,
        Box::new(|fx| buffer(SENTINEL_U64, 4, |b, _| kdw_engine_get_collider_ids(fx.a, b, 4, null_mut()))),
    ));
    for cap in [0u32, 1] {
        c.push(case(
            "kdw_engine_get_collider_ids",
            format!("count:capacity={cap}"),
            small,
            Box::new(move |fx| buffer(SENTINEL_U64, 4, |b, w| kdw_engine_get_collider_ids(fx.a, b, cap, w))),
        ));
    }

    // -- per-joint radii (the fixture's chains have N joints)
    let radii = [0.01f32; N as usize + 1];
    c.push(case(
        "kdw_chain_set_joint_radii",
        "null:engine",
        nullp,
        Box::new(move |fx| (kdw_chain_set_joint_radii(null_mut(), fx.chain, radii.as_ptr(), N), true)),
    ));
    c.push(case(
        "kdw_chain_set_joint_radii",
        "null:radii",
        nullp,
        Box::new(|fx| (kdw_chain_set_joint_radii(fx.a, fx.chain, null(), N), true)),
    ));
    for count in [1u32, N - 1, N + 1] {
        c.push(case(
            "kdw_chain_set_joint_radii",
            format!("count:count={count}"),
            badarg,
            Box::new(move |fx| (kdw_chain_set_joint_radii(fx.a, fx.chain, radii.as_ptr(), count), true)),
        ));
    }
    let bad_radii = BAD_FLOATS.into_iter().chain([("range", -0.01f32), ("range", -0.0 - 1e-30), ("huge", 1e7)]);
    for (tag, r) in bad_radii {
        for joint in [0usize, N as usize - 1] {
            c.push(case(
                "kdw_chain_set_joint_radii",
                format!("{tag}:radii"),
                badarg,
                Box::new(move |fx| {
                    let mut radii = [0.01f32; N as usize];
                    radii[joint] = r;
                    (kdw_chain_set_joint_radii(fx.a, fx.chain, radii.as_ptr(), N), true)
                }),
            ));
        }
    }

    // -- teleports
    c.push(case("kdw_engine_teleport", "null:engine", nullp, Box::new(|_| (kdw_engine_teleport(null_mut()), true))));
    c.push(case(
        "kdw_chain_teleport",
        "null:engine",
        nullp,
        Box::new(|fx| (kdw_chain_teleport(null_mut(), fx.chain), true)),
    ));
    for (tag, id) in fx.bad_chain_ids() {
        let t = format!("{tag}:chain");
        c.push(case("kdw_chain_teleport", t.clone(), badid, Box::new(move |fx| (kdw_chain_teleport(fx.a, id), true))));
        c.push(case(
            "kdw_chain_set_joint_radii",
            t.clone(),
            badid,
            Box::new(move |fx| (kdw_chain_set_joint_radii(fx.a, id, radii.as_ptr(), N), true)),
        ));
    }
}

/// `kdw_engines_step` over the fixture's two engines: one bad handle, input or count fails the whole call.
fn engines_step_cases(c: &mut Vec<Case>) {
    let (nullp, badarg) = (KDW_STATUS_NULL_POINTER, KDW_STATUS_INVALID_ARGUMENT);
    let references = [head(); 2];
    let both = |fx: &Fixture| [fx.a, fx.b];
    c.push(case(
        "kdw_engines_step",
        "null:engines",
        nullp,
        Box::new(move |_| (kdw_engines_step(null(), 2, 0.1, &camera(), references.as_ptr()), true)),
    ));
    c.push(case(
        "kdw_engines_step",
        "null:engines[1]",
        nullp,
        Box::new(move |fx| {
            (kdw_engines_step([fx.a, null_mut()].as_ptr(), 2, 0.1, &camera(), references.as_ptr()), true)
        }),
    ));
    c.push(case(
        "kdw_engines_step",
        "null:camera_position",
        nullp,
        Box::new(move |fx| (kdw_engines_step(both(fx).as_ptr(), 2, 0.1, null(), references.as_ptr()), true)),
    ));
    c.push(case(
        "kdw_engines_step",
        "null:view_references",
        nullp,
        Box::new(move |fx| (kdw_engines_step(both(fx).as_ptr(), 2, 0.1, &camera(), null()), true)),
    ));
    c.push(case(
        "kdw_engines_step",
        "count:count=repeated",
        badarg,
        Box::new(move |fx| (kdw_engines_step([fx.a, fx.a].as_ptr(), 2, 0.1, &camera(), references.as_ptr()), true)),
    ));
    for (tag, dt) in BAD_FLOATS.into_iter().chain([("range", -1e-6f32)]) {
        c.push(case(
            "kdw_engines_step",
            format!("{tag}:dt"),
            badarg,
            Box::new(move |fx| (kdw_engines_step(both(fx).as_ptr(), 2, dt, &camera(), references.as_ptr()), true)),
        ));
    }
    for (tag, p) in bad_vec3s() {
        c.push(case(
            "kdw_engines_step",
            format!("{tag}:camera_position"),
            badarg,
            Box::new(move |fx| (kdw_engines_step(both(fx).as_ptr(), 2, 0.1, &p, references.as_ptr()), true)),
        ));
    }
    for (tag, t) in bad_transforms() {
        c.push(case(
            "kdw_engines_step",
            format!("{tag}:view_references"),
            badarg,
            Box::new(move |fx| (kdw_engines_step(both(fx).as_ptr(), 2, 0.1, &camera(), [head(), t].as_ptr()), true)),
        ));
    }
}

/// Covered outside the table (they do not fail in the usual way): `kdw_chain_is_valid` answers 0 for bad
/// ids; `kdw_last_error_message` reports errors itself; the constant queries have nothing to reject.
fn special_tags() -> BTreeMap<&'static str, Vec<String>> {
    let mut m = BTreeMap::new();
    m.insert(
        "kdw_view_shape_is_valid",
        ["zero", "stale", "foreign", "kind"].iter().map(|t| format!("{t}:view_shape")).collect(),
    );
    // Documented: NULL is a no-op returning OK, like free(NULL) (`destroy_null_is_a_no_op`).
    m.insert("kdw_engine_destroy", vec!["null:engine".into()]);
    m.insert("kdw_chain_is_valid", ["zero", "stale", "foreign", "kind"].iter().map(|t| format!("{t}:chain")).collect());
    m.insert(
        "kdw_collider_is_valid",
        ["zero", "stale", "foreign", "kind"].iter().map(|t| format!("{t}:collider")).collect(),
    );
    m.insert("kdw_last_error_message", vec!["null:buffer".into(), "null:out_length".into(), "count:capacity".into()]);
    for f in [
        "kdw_chain_def_default",
        "kdw_engine_def_default",
        "kdw_abi_version",
        "kdw_version_string",
        "kdw_simd_path",
        "kdw_portable_determinism",
        "kdw_status_str",
        "kdw_stroke_camera_default",
        "kdw_collider_def_default",
    ] {
        m.insert(f, vec!["call".into()]);
    }
    m
}

// ---- tests --------------------------------------------------------------------------------------------

#[test]
fn every_header_function_is_covered() {
    let text = header_text();
    let functions = parse_functions(&text);
    let floats = struct_float_fields(&text);
    assert!(functions.len() >= 30, "header parse found only {} functions", functions.len());
    assert!(floats.get("kdw_chain_def").is_some_and(|f| f.contains(&"stiffness".to_string())), "{floats:?}");
    let fx = Fixture::new();
    let mut covered: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for case in cases(&fx) {
        covered.entry(case.function.to_string()).or_default().insert(case.tag.split('=').next().unwrap().to_string());
    }
    for (f, tags) in special_tags() {
        covered.entry(f.to_string()).or_default().extend(tags);
    }
    let mut missing = Vec::new();
    for f in &functions {
        let have = covered.get(&f.name).cloned().unwrap_or_default();
        for tag in required_tags(f, &floats) {
            if !have.contains(&tag) {
                missing.push(format!("{}: {tag}", f.name));
            }
        }
    }
    let names: BTreeSet<&str> = functions.iter().map(|f| f.name.as_str()).collect();
    let stale: Vec<&String> = covered.keys().filter(|k| !names.contains(k.as_str())).collect();
    println!("header: {} functions; table: {} cases", functions.len(), cases(&fx).len());
    assert!(missing.is_empty(), "uncovered (function: required case):\n{}", missing.join("\n"));
    assert!(stale.is_empty(), "cases for functions not in the header: {stale:?}");
}

/// Sets a recognisable last-error message, so that a rejected call that forgets to set its own is caught.
fn set_marker() {
    let def = kdw_engine_def { struct_size: MARKER.parse().unwrap(), ..kdw_engine_def_default() };
    let mut engine = null_mut();
    assert_eq!(kdw_engine_create(&def, &mut engine), KDW_STATUS_STRUCT_SIZE_MISMATCH);
    assert!(last_error().contains(MARKER));
}

#[test]
fn every_bad_input_is_rejected_cleanly() {
    let fx = Fixture::new();
    let all = cases(&fx);
    let mut failures = Vec::new();
    let mut per_status: BTreeMap<kdw_status, usize> = BTreeMap::new();
    for case in &all {
        let before = fx.hashes();
        set_marker();
        let (status, untouched) = (case.run)(&fx);
        let message = last_error();
        let after = fx.hashes();
        let label = format!("{} [{}]", case.function, case.tag);
        *per_status.entry(status).or_default() += 1;
        if status == KDW_STATUS_OK || status == KDW_STATUS_PANIC || status != case.expected {
            failures.push(format!("{label}: status {status}, expected {} ({message})", case.expected));
        }
        if message.is_empty() || message.contains(MARKER) {
            failures.push(format!("{label}: no error message of its own (got {message:?})"));
        }
        if before != after {
            failures.push(format!("{label}: state hash changed"));
        }
        if !untouched {
            failures.push(format!("{label}: an output was written"));
        }
    }
    println!("{} bad-input cases; statuses returned: {per_status:?}", all.len());
    for f in &failures {
        println!("FAIL {f}");
    }
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), all.len(), failures.join("\n"));
}

#[test]
fn destroy_null_is_a_no_op() {
    assert_eq!(kdw_engine_destroy(null_mut()), KDW_STATUS_OK);
}

/// `kdw_chain_is_valid` / `kdw_view_shape_is_valid` / `kdw_collider_is_valid` answer 0 (status OK) for every bad
/// id, 1 for a good one.
#[test]
fn is_valid_answers_zero_for_bad_ids() {
    let fx = Fixture::new();
    let before = fx.hashes();
    for (tag, id) in fx.bad_chain_ids() {
        let mut valid = SENTINEL_U32;
        assert_eq!(kdw_chain_is_valid(fx.a, id, &mut valid), KDW_STATUS_OK, "{tag}");
        assert_eq!(valid, 0, "{tag} chain id reported valid");
    }
    for (tag, id) in fx.bad_view_ids() {
        let mut valid = SENTINEL_U32;
        assert_eq!(kdw_view_shape_is_valid(fx.a, id, &mut valid), KDW_STATUS_OK, "{tag}");
        assert_eq!(valid, 0, "{tag} view shape id reported valid");
    }
    for (tag, id) in fx.bad_collider_ids() {
        let mut valid = SENTINEL_U32;
        assert_eq!(kdw_collider_is_valid(fx.a, id, &mut valid), KDW_STATUS_OK, "{tag}");
        assert_eq!(valid, 0, "{tag} collider id reported valid");
    }
    let mut valid = 0;
    assert_eq!(kdw_collider_is_valid(fx.a, fx.collider, &mut valid), KDW_STATUS_OK);
    assert_eq!(valid, 1);
    assert_eq!(kdw_collider_is_valid(fx.b, fx.foreign_collider, &mut valid), KDW_STATUS_OK);
    assert_eq!(valid, 1);
    assert_eq!(kdw_chain_is_valid(fx.a, fx.chain, &mut valid), KDW_STATUS_OK);
    assert_eq!(valid, 1);
    assert_eq!(kdw_view_shape_is_valid(fx.a, fx.view, &mut valid), KDW_STATUS_OK);
    assert_eq!(valid, 1);
    assert_eq!(fx.hashes(), before);
}

/// `kdw_last_error_message`: NULL buffer with a capacity, truncation, NULL `out_length`, length query.
#[test]
fn last_error_message_contract() {
    set_marker();
    let mut length = SENTINEL_U32;
    assert_eq!(kdw_last_error_message(null_mut(), 16, &mut length), KDW_STATUS_NULL_POINTER);
    assert_eq!(length, SENTINEL_U32, "out_length written on failure");
    assert_eq!(kdw_last_error_message(null_mut(), 0, &mut length), KDW_STATUS_OK);
    let full = length as usize;
    assert!(full > 10);
    let mut small = [1 as c_char; 8];
    assert_eq!(kdw_last_error_message(small.as_mut_ptr(), 8, null_mut()), KDW_STATUS_BUFFER_TOO_SMALL);
    assert_eq!(small[7], 0, "truncated message must stay NUL-terminated");
    let mut exact = vec![1 as c_char; full];
    assert_eq!(kdw_last_error_message(exact.as_mut_ptr(), full as u32, &mut length), KDW_STATUS_BUFFER_TOO_SMALL);
    let mut fits = vec![1 as c_char; full + 1];
    assert_eq!(kdw_last_error_message(fits.as_mut_ptr(), full as u32 + 1, null_mut()), KDW_STATUS_OK);
    assert!(last_error().contains(MARKER), "reading the message must not change it");
}

/// The baseline calls the sketch cases break are valid.
#[test]
fn sketch_baselines_are_valid() {
    let (status, untouched) = Stroke::valid().call();
    assert_eq!(status, KDW_STATUS_OK, "{}", last_error());
    assert!(!untouched);
    let mut pixel = kdw_vec2::default();
    assert_eq!(
        kdw_stroke_camera_project(&kdw_stroke_camera_default(), &vec3(0.0, 0.0, -3.0), &mut pixel),
        KDW_STATUS_OK
    );
}

/// The constant queries answer for any input.
#[test]
fn constant_queries() {
    assert_eq!(kdw_stroke_camera_default().struct_size as usize, size_of::<kdw_stroke_camera>());
    for status in [i32::MIN, -101, -100, -7, -6, -1, 0, 1, 42, i32::MAX] {
        let s = kdw_status_str(status);
        assert!(!s.is_null());
        // SAFETY: static NUL-terminated string.
        assert!(!unsafe { CStr::from_ptr(s) }.to_bytes().is_empty(), "{status}");
    }
    assert_eq!(kdw_abi_version(), KDW_ABI_VERSION);
    // SAFETY: static NUL-terminated string.
    let version = unsafe { CStr::from_ptr(kdw_version_string()) }.to_str().unwrap();
    assert_eq!(version, env!("CARGO_PKG_VERSION"));
    // SAFETY: static NUL-terminated string.
    let simd = unsafe { CStr::from_ptr(kdw_simd_path()) }.to_str().unwrap();
    assert!(["avx512", "avx2", "sse2", "neon", "scalar"].contains(&simd), "kdw_simd_path() = {simd:?}");
    assert_eq!(simd, kodawari::simd_path());
    assert_eq!(kdw_portable_determinism(), u32::from(cfg!(feature = "portable-determinism")));
    assert_eq!(kdw_engine_def_default().struct_size as usize, size_of::<kdw_engine_def>());
    assert_eq!(kdw_chain_def_default().struct_size as usize, size_of::<kdw_chain_def>());
    assert_eq!(kdw_collider_def_default().struct_size as usize, size_of::<kdw_collider_def>());
}

type Setup = Box<dyn Fn(*mut kdw_engine, u64) -> kdw_status>;

/// Steps a 5-joint chain for 2 s after `setup`; returns the failures (a non-finite read-back).
fn run_valid_extremes(scenarios: Vec<(&str, Setup)>) -> Vec<String> {
    let mut failures = Vec::new();
    for (name, setup) in scenarios {
        let engine = new_engine();
        let chain = new_chain(engine, N);
        let status = setup(engine, chain);
        if status != KDW_STATUS_OK {
            println!("{name}: rejected with {status} ({})", last_error());
            kdw_engine_destroy(engine);
            continue;
        }
        let mut finite = true;
        for frame in 0..120 {
            let k = kdw_transform { position: vec3(0.1 * (frame as f32 * 0.2).sin(), 1.6, 0.0), ..head() };
            let status = kdw_engine_step(engine, 1.0 / 60.0, &camera(), &k);
            let mut out = vec![kdw_transform::default(); N as usize];
            let mut written = 0;
            kdw_engine_read_world(engine, out.as_mut_ptr(), N, &mut written);
            let mut energy = 0.0;
            kdw_chain_kinetic_energy(engine, chain, &mut energy);
            let ok = status == KDW_STATUS_OK
                && energy.is_finite()
                && out.iter().all(|t| {
                    [t.position.x, t.position.y, t.position.z, t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w]
                        .iter()
                        .all(|v| v.is_finite())
                });
            if !ok {
                failures.push(format!("{name}: non-finite at frame {frame} (status {status}, KE {energy})"));
                finite = false;
                break;
            }
        }
        println!("{name}: accepted; 120 frames {}", if finite { "finite" } else { "NOT finite" });
        kdw_engine_destroy(engine);
    }
    failures
}

/// A particle radius of 1e30 m is inside the documented range (">= 0", finite) but the orientation weight
/// `radius^2 / 5` overflows float32 and the chain turns NaN on the first step.
#[test]
fn huge_radius_stays_finite() {
    let failures = run_valid_extremes(vec![
        (
            "radius 1e20",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { radius: 1e20, ..kdw_chain_def_default() })),
        ),
        (
            "radius 1e30",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { radius: 1e30, ..kdw_chain_def_default() })),
        ),
    ]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// Gravity has no documented range beyond "finite"; a huge one overflows the velocities. Found by the
/// fuzzer: default engine, `kdw_engine_set_gravity({0, 0, 1e30})`, a 13-joint chain, one step of 0.15 s:
/// `kdw_chain_kinetic_energy` returns +Inf.
#[test]
fn huge_gravity_stays_finite() {
    let failures = run_valid_extremes(vec![
        ("gravity 1e30 along z", Box::new(|e, _| kdw_engine_set_gravity(e, &vec3(0.0, 0.0, 1e30)))),
        ("gravity 1e15 along z", Box::new(|e, _| kdw_engine_set_gravity(e, &vec3(0.0, 0.0, 1e15)))),
        ("gravity -1e30 along y", Box::new(|e, _| kdw_engine_set_gravity(e, &vec3(0.0, -1e30, 0.0)))),
    ]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// A mass of f32::MAX is inside the documented range ("> 0"); `kdw_chain_kinetic_energy` (mass * v^2 / 2)
/// then overflows to +Inf as soon as the chain moves. Found by the fuzzer.
#[test]
fn huge_mass_kinetic_energy_stays_finite() {
    let failures = run_valid_extremes(vec![(
        "mass f32::MAX",
        Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { mass: f32::MAX, ..kdw_chain_def_default() })),
    )]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// A mass of 1e-40 kg is inside the documented range ("> 0") but its inverse overflows float32: the first
/// step turns the dynamic joints NaN. Found by the fuzzer.
#[test]
fn tiny_mass_stays_finite() {
    let failures = run_valid_extremes(vec![
        (
            "mass 1e-40",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { mass: 1e-40, ..kdw_chain_def_default() })),
        ),
        (
            "mass 1e-39",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { mass: 1e-39, ..kdw_chain_def_default() })),
        ),
    ]);
    assert!(failures.is_empty(), "{failures:?}");
}

/// Values at the edge of validity are accepted and must not turn the state non-finite (SPEC 3.9: "the
/// engine never produces NaN or Inf from valid input").
#[test]
fn extreme_valid_values_stay_finite() {
    let scenarios: Vec<(&str, Setup)> = vec![
        ("gravity 1e4 along z", Box::new(|e, _| kdw_engine_set_gravity(e, &vec3(0.0, 0.0, 1e4)))),
        (
            "gravity 1e6 x gravity_scale 100",
            Box::new(|e, c| {
                kdw_engine_set_gravity(e, &vec3(0.0, -1e6, 0.0));
                kdw_chain_set_def(e, c, &kdw_chain_def { gravity_scale: 100.0, ..kdw_chain_def_default() })
            }),
        ),
        (
            "mass 1e-30",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { mass: 1e-30, ..kdw_chain_def_default() })),
        ),
        (
            "radius 1e15",
            Box::new(|e, c| kdw_chain_set_def(e, c, &kdw_chain_def { radius: 1e15, ..kdw_chain_def_default() })),
        ),
        (
            "influence 1e30",
            Box::new(|e, c| {
                let mut id = 0;
                let shape = joints(N, 1.0);
                kdw_chain_add_view_shape(e, c, &vec3(0.0, 0.0, 1.0), shape.as_ptr(), N, 1e30, &mut id)
            }),
        ),
    ];
    let failures = run_valid_extremes(scenarios);
    assert!(failures.is_empty(), "{failures:?}");
}
