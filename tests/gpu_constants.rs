//! One source for every constant shared by Rust and the WGSL (issue 42 item 3): every
//! module-scope `const` of every shader, as naga evaluates it, is either its Rust twin
//! bit for bit (src/gpu/constants.rs `shared`) or listed below as WGSL-only with its
//! reason. Needs no GPU.

use std::collections::BTreeMap;

use talus::gpu::constants::{Value, shared};
use talus::gpu::modules::MODULES;

/// Module-scope WGSL constants with no Rust twin, each with the reason. None at present:
/// every `const` of the shaders mirrors a Rust value. A new WGSL-only constant goes here
/// with why Rust has no use for it; one that mirrors a Rust value goes into
/// src/gpu/constants.rs instead.
const WGSL_ONLY: &[(&str, &str)] = &[];

/// The pipeline-overridable constants (`override`): each pipeline sets them by name from
/// Rust (src/gpu/kernels.rs `Pipelines::new`: the build's shapes, walls and law, and
/// per kernel `RECORD`, `AHEAD`, `PAIRS_PER_THREAD`), so the WGSL holds only a default.
/// `LAW`'s default is `LAW_ANY`, a checked constant.
const OVERRIDES: &[&str] = &[
    "RECORD",
    "AHEAD",
    "LAW",
    "PAIRS_PER_THREAD",
    "POLYGONS",
    "POLYGON_SHAPES",
    "DISK_SHAPES",
    "WALLS",
    "SPHEROPOLYGONS",
];

fn parse(name: &str, src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(src)))
}

/// A constant's value after naga's constant evaluation (a literal for a scalar `const`,
/// whatever expression it was written as: `3.0 / 20.0`, `2u * MAX_PAIR_SLOTS`).
fn value(module: &naga::Module, init: naga::Handle<naga::Expression>) -> Result<Value, String> {
    use naga::Literal as L;
    match &module.global_expressions[init] {
        naga::Expression::Literal(L::U32(v)) => Ok(Value::U32(*v)),
        naga::Expression::Literal(L::I32(v)) => Ok(Value::I32(*v)),
        naga::Expression::Literal(L::F32(v)) => Ok(Value::F32(*v)),
        other => Err(format!(
            "{other:?}: not a u32, i32 or f32 scalar (declare it with one of these types, \
             or teach tests/gpu_constants.rs `value` its form)"
        )),
    }
}

/// Every module-scope `const` of the assembled modules: name → (value, first module).
fn wgsl_constants() -> BTreeMap<String, (Value, &'static str)> {
    let mut out: BTreeMap<String, (Value, &'static str)> = BTreeMap::new();
    for m in MODULES {
        let module = parse(m.name, &m.source());
        for (_, c) in module.constants.iter() {
            let Some(name) = c.name.clone() else { continue };
            let v = value(&module, c.init).unwrap_or_else(|e| panic!("{name} ({}): {e}", m.name));
            if let Some((old, first)) = out.get(&name) {
                assert_eq!(
                    *old, v,
                    "{name} is {old} in module {first} but {v} in module {}",
                    m.name
                );
            } else {
                out.insert(name, (v, m.name));
            }
        }
    }
    out
}

/// The shader files on disk, by file name.
fn shader_files() -> Vec<(String, String)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    files.sort();
    assert!(files.len() > 10, "the shaders in {}", dir.display());
    files
}

#[test]
fn every_wgsl_constant_is_its_rust_twin() {
    let wgsl = wgsl_constants();
    let rust = shared();
    let mut failures = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (name, r) in &rust {
        assert!(
            seen.insert(*name),
            "{name} is twice in src/gpu/constants.rs"
        );
        match wgsl.get(*name) {
            Some((w, module)) if w != r => failures.push(format!(
                "{name}: WGSL {w} (module {module}), Rust {r} (src/gpu/constants.rs)"
            )),
            Some(_) => {}
            None => failures.push(format!(
                "{name}: in src/gpu/constants.rs, but no shader declares it"
            )),
        }
    }
    for (name, (w, module)) in &wgsl {
        let checked = rust.iter().any(|(n, _)| n == name);
        let only = WGSL_ONLY.iter().any(|(n, _)| n == name);
        if !checked && !only {
            failures.push(format!(
                "{name} = {w} (module {module}): neither checked against Rust \
                 (src/gpu/constants.rs `shared`) nor listed as WGSL-only \
                 (tests/gpu_constants.rs WGSL_ONLY)"
            ));
        }
        if checked && only {
            failures.push(format!("{name}: both checked and listed as WGSL-only"));
        }
    }
    for (name, why) in WGSL_ONLY {
        assert!(!why.is_empty(), "{name}: WGSL_ONLY without a reason");
        if !wgsl.contains_key(*name) {
            failures.push(format!(
                "{name}: listed as WGSL-only, but no shader declares it"
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "constants of the WGSL against Rust:\n  {}",
        failures.join("\n  ")
    );
    println!("{} WGSL constants checked against Rust", rust.len());
}

#[test]
fn every_shader_file_is_assembled_and_declares_constants_at_module_scope() {
    // Every file of shaders/ is a part of some module, so `wgsl_constants` sees its
    // constants; and every `const` is declared at module scope, where naga keeps it by
    // name (a function's `const` is folded away unseen): the names the files declare are
    // exactly the names naga found.
    let wgsl = wgsl_constants();
    let mut declared = std::collections::BTreeSet::new();
    for (file, text) in shader_files() {
        assert!(
            MODULES.iter().any(|m| m.parts.contains(&text.as_str())),
            "shaders/{file} is in no module of src/gpu/kernels.rs MODULES"
        );
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            let trimmed = code.trim_start();
            if !trimmed.starts_with("const ") {
                continue;
            }
            assert!(
                trimmed.len() == code.len(),
                "shaders/{file}:{}: a `const` inside a function escapes the check; \
                 declare it at module scope",
                n + 1
            );
            let name = trimmed["const ".len()..]
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .next()
                .unwrap();
            declared.insert(name.to_string());
        }
    }
    let found: std::collections::BTreeSet<String> = wgsl.keys().cloned().collect();
    assert_eq!(declared, found, "the files' `const` names against naga's");
}

#[test]
fn every_override_is_one_rust_sets() {
    let mut found = std::collections::BTreeSet::new();
    for m in MODULES {
        let module = parse(m.name, &m.source());
        for (_, o) in module.overrides.iter() {
            let name = o.name.clone().unwrap_or_default();
            assert!(
                OVERRIDES.contains(&name.as_str()),
                "override {name} (module {}) is not in tests/gpu_constants.rs OVERRIDES",
                m.name
            );
            found.insert(name);
        }
    }
    for name in OVERRIDES {
        assert!(found.contains(*name), "no shader declares override {name}");
    }
}

#[test]
fn what_the_wgsl_takes_for_granted() {
    use talus::integrate::gear::{CORRECTOR, PREDICTOR};
    // correct.wgsl adds Δ to q2 without a product, and predict.wgsl the values to q0.
    assert_eq!(CORRECTOR[2], 1.0, "correct.wgsl takes c2 = 1");
    for (l, p) in PREDICTOR[0].iter().enumerate().skip(1) {
        assert_eq!(*p, 1.0, "predict.wgsl takes C({l}, 0) = 1");
    }
    // common.wgsl holds a pair's sub-contact springs in a vec4 (`SubSprings`).
    assert_eq!(
        talus::cpu::springs::MAX_SUB,
        4,
        "SubSprings holds MAX_SUB in a vec4"
    );
    // polygon.wgsl keeps a bit per edge and two per crossing of a polygon in a u32, and
    // an edge's number in four bits.
    const {
        assert!(
            talus::shape::MAX_CORNERS <= 16,
            "polygon.wgsl's masks hold 16 corners"
        )
    };
}
