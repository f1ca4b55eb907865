//! The shape of the house (issue 42): the top-level modules of `src/` in layers that
//! only look down, no import cycle among them or among the files of one directory, no
//! file past the size limit, and no new file at the top of `src/`. The size and
//! top-level checks hold their exceptions in lists that may only shrink: a file not
//! listed fails the test, and so does a listed one that is gone.
//!
//! The module graph is read from the sources: a file's module is its path (`src/a/b.rs`
//! is `a::b`, `src/a/mod.rs` is `a`), and it depends on every module it names through
//! `crate::…` or `super::…` paths, in `use` declarations (braces expanded) and in code,
//! outside comments and its `#[cfg(test)]` module. Cycles are the strongly connected
//! components of two graphs, as the issue counts them: the top-level modules of the
//! crate, and the files inside each directory module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level modules in layers, lowest first: each may name only modules before it
/// (`layers_only_look_down`), so the graph has no cycle among them. A new module must be
/// placed here. ARCHITECTURE.md, "Modules", draws the same list.
const LAYERS: &[&str] = &[
    "base",      // vectors, rng, files, progress, provenance, threads
    "shape",     // polygons, spheropolygons
    "law",       // contact laws and the contact block's spec
    "overlap",   // contact geometry, one query per file
    "state",     // the particles
    "integrate", // Gear, leapfrog
    "scene",     // the scene: schema, checks, its one law
    "cpu",       // the CPU path's stages
    "create",    // particles from the scene's blocks
    "sim",       // one step, in stage order
    "gpu",       // the GPU path
    "io",        // snapshot and checkpoint formats
    "analyze",   // measures of a snapshot
    "render",    // pictures and plots
    "reproduce", // R1-R9
    "run",       // the run loop and its outputs
    "sweep",     // seeds and parameters, Slurm
    "bench",     // talus bench
];

/// Files over `MAX_LINES` today, with the most lines each may have; issue 42 splits
/// them. A file not listed that grows past the limit fails, and so does a listed one
/// that grows.
const MAX_LINES: usize = 700;
const OVERSIZED: &[(&str, usize)] = &[];

/// The `.rs` files at the top of `src/` today; issue 42 moves them into layers (at most
/// 8). A new one fails.
const TOP_LEVEL: &[&str] = &["lib.rs", "main.rs", "state.rs"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `src/a/b.rs` → ["a", "b"]; `src/a/mod.rs` → ["a"]; `src/lib.rs` → [].
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string literals and its `#[cfg(test)]` module.
fn code(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]") {
            // Skip the item that follows: to the end of its braces.
            let mut depth = 0i32;
            let mut opened = false;
            for l in lines.by_ref() {
                depth += l.matches('{').count() as i32 - l.matches('}').count() as i32;
                opened |= l.contains('{');
                if opened && depth <= 0 || !opened && l.trim_end().ends_with(';') {
                    break;
                }
            }
            continue;
        }
        let mut in_str = false;
        let mut prev = ' ';
        let mut kept = String::new();
        let chars: Vec<char> = line.chars().collect();
        let mut k = 0;
        while k < chars.len() {
            let c = chars[k];
            if !in_str && c == '/' && chars.get(k + 1) == Some(&'/') {
                break;
            }
            if c == '"' && prev != '\\' && !(prev == '\'' && chars.get(k + 1) == Some(&'\'')) {
                in_str = !in_str;
            } else if !in_str {
                kept.push(c);
            }
            prev = c;
            k += 1;
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// Expands a `use` tree's text (`crate::{a::b, c}`) into its paths.
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.to_string()];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    (parts.into_iter())
        .filter(|p| !p.trim().is_empty())
        .flat_map(|p| expand(p).into_iter().map(|e| format!("{prefix}{e}")))
        .collect()
}

/// Every `crate::…`/`super::…`/`self::…` path the code names, as written.
fn paths(code: &str) -> Vec<String> {
    let mut found = Vec::new();
    // `use` declarations, braces expanded.
    let mut rest = code;
    while let Some(at) = rest.find("use ") {
        let before = rest[..at].chars().last();
        rest = &rest[at + 4..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let end = rest.find(';').unwrap_or(rest.len());
        found.extend(expand(&rest[..end].replace(char::is_whitespace, "")));
    }
    // Paths in code.
    for key in ["crate::", "super::"] {
        let mut rest = code;
        while let Some(at) = rest.find(key) {
            let before = rest[..at].chars().last();
            let tail = &rest[at..];
            let end = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            if !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                found.push(tail[..end].to_string());
            }
            rest = &rest[at + key.len()..];
        }
    }
    found
}

/// The module a path names, resolved from module `from`: its segments from the crate
/// root, as far as they go (`super` is the parent of the module, whichever file holds
/// it; `self` the module itself).
fn resolve(path: &str, from: &[String]) -> Option<Vec<String>> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut base = match *segs.first()? {
        "crate" => Vec::new(),
        "super" | "self" => from.to_vec(),
        _ => return None,
    };
    let mut k = usize::from(segs[0] == "crate");
    while k < segs.len() && (segs[k] == "super" || segs[k] == "self") {
        if segs[k] == "super" {
            base.pop()?;
        }
        k += 1;
    }
    base.extend(segs[k..].iter().map(|s| s.to_string()));
    Some(base)
}

struct Graph {
    /// Module (joined by ::) → the modules it depends on.
    edges: BTreeMap<String, BTreeSet<String>>,
}

/// The strongly connected components with more than one member (Tarjan).
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let n = t.index.len();
        t.index.insert(v, n);
        t.low.insert(v, n);
        t.stack.push(v);
        t.on.insert(v);
        for w in t.g.edges.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.on.contains(w) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.edges.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out.sort();
    t.out
}

/// The two graphs: top-level modules, and the files inside each directory module.
fn graphs() -> (Graph, BTreeMap<String, Graph>) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    // Every module that has a file, to resolve a path to the longest module it names.
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
    let mut top = Graph {
        edges: BTreeMap::new(),
    };
    let mut inner: BTreeMap<String, Graph> = BTreeMap::new();
    for f in &files {
        if f.file_name().is_some_and(|n| n == "main.rs") {
            continue; // the binary, above the library
        }
        let from = module_of(&src, f);
        if from.is_empty() || from.first().is_some_and(|m| m == "bin") {
            continue;
        }
        let text = std::fs::read_to_string(f).unwrap();
        for p in paths(&code(&text)) {
            let Some(mut target) = resolve(&p, &from) else {
                continue;
            };
            while !target.is_empty() && !modules.contains(&target) {
                target.pop();
            }
            if target.is_empty() {
                continue;
            }
            if target[0] != from[0] {
                top.edges
                    .entry(from[0].clone())
                    .or_default()
                    .insert(target[0].clone());
            } else if from.len() >= 2 && target.len() >= 2 && target[1] != from[1] {
                let g = inner.entry(from[0].clone()).or_insert(Graph {
                    edges: BTreeMap::new(),
                });
                let name = |m: &[String]| format!("{}::{}", m[0], m[1]);
                g.edges
                    .entry(name(&from))
                    .or_default()
                    .insert(name(&target));
            }
        }
    }
    (top, inner)
}

#[test]
fn the_module_graph_has_no_cycles() {
    let (top, inner) = graphs();
    assert!(
        top.edges.len() > 10,
        "the graph was read: {:?}",
        top.edges.keys()
    );
    let mut found: Vec<Vec<String>> = cycles(&top);
    for g in inner.values() {
        found.extend(cycles(g));
    }
    assert!(found.is_empty(), "import cycles: {found:?}");
}

#[test]
fn layers_only_look_down() {
    let (top, _) = graphs();
    let layer = |m: &str| LAYERS.iter().position(|&l| l == m);
    let mut unplaced = BTreeSet::new();
    let mut upward = Vec::new();
    for (from, tos) in &top.edges {
        for to in tos {
            match (layer(from), layer(to)) {
                (Some(a), Some(b)) if b >= a => upward.push(format!("{from} -> {to}")),
                (None, _) => drop(unplaced.insert(from.clone())),
                (_, None) => drop(unplaced.insert(to.clone())),
                _ => {}
            }
        }
    }
    assert!(
        unplaced.is_empty() && upward.is_empty(),
        "modules not in LAYERS: {unplaced:?}\nnames of a module in a higher layer: {upward:?}"
    );
}

#[test]
fn the_cycle_finder_finds_a_cycle_and_only_one() {
    let mut edges = BTreeMap::new();
    for (a, b) in [("a", "b"), ("b", "c"), ("c", "a"), ("c", "d"), ("d", "e")] {
        edges
            .entry(a.to_string())
            .or_insert_with(BTreeSet::new)
            .insert(b.to_string());
    }
    let g = Graph { edges };
    assert_eq!(cycles(&g), vec![vec!["a", "b", "c"]]);
    // Paths as a file writes them.
    let text = "use crate::{a::B, c::{d, e::F}};\nuse super::x;\n// crate::comment\nfn f() { crate::g::h(); }\n#[cfg(test)]\nmod tests {\n use crate::t;\n}\n";
    let p = paths(&code(text));
    for want in [
        "crate::a::B",
        "crate::c::d",
        "crate::c::e::F",
        "super::x",
        "crate::g::h",
    ] {
        assert!(p.iter().any(|x| x == want), "{want} in {p:?}");
    }
    assert!(
        !p.iter().any(|x| x.contains("comment") || x == "crate::t"),
        "{p:?}"
    );
    let from = ["a".to_string(), "b".to_string()];
    assert_eq!(
        resolve("super::x", &from),
        Some(vec!["a".into(), "x".into()])
    );
    assert_eq!(resolve("super::x", &from[..1]), Some(vec!["x".into()]));
    assert_eq!(
        resolve("self::y", &from[..1]),
        Some(vec!["a".into(), "y".into()])
    );
}

#[test]
fn no_file_grows_past_the_size_limit() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut over = Vec::new();
    for f in &files {
        let lines = std::fs::read_to_string(f).unwrap().lines().count();
        let name = f
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let limit = (OVERSIZED.iter().find(|o| o.0 == name)).map_or(MAX_LINES, |o| o.1);
        if lines > limit {
            over.push(format!("src/{name}: {lines} lines (at most {limit})"));
        }
    }
    let gone: Vec<_> = (OVERSIZED.iter())
        .filter(|o| !src.join(o.0).is_file())
        .collect();
    assert!(
        over.is_empty() && gone.is_empty(),
        "{}\nlisted but gone: {gone:?}",
        over.join("\n")
    );
}

#[test]
fn no_new_file_at_the_top_of_src() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut top: Vec<String> = (std::fs::read_dir(&src).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "rs"))
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    top.sort();
    let new: Vec<_> = top
        .iter()
        .filter(|f| !TOP_LEVEL.contains(&f.as_str()))
        .collect();
    let gone: Vec<_> = TOP_LEVEL
        .iter()
        .filter(|f| !top.iter().any(|t| t == *f))
        .collect();
    assert!(
        new.is_empty() && gone.is_empty(),
        "new files at the top of src/ (put them in a layer): {new:?}\nlisted but gone: {gone:?}"
    );
}

/// The library does not depend on clap: only the binary (`src/main.rs`, `src/cli/`)
/// parses a command line, so a program that links `talus` gets no argument parser.
#[test]
fn only_the_binary_names_clap() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut named = Vec::new();
    for f in &files {
        let module = module_of(&src, f);
        if module.first().is_some_and(|m| m == "cli") || f.ends_with("main.rs") {
            continue;
        }
        let text = code(&std::fs::read_to_string(f).unwrap());
        if text.contains("clap::") || text.contains("use clap") {
            named.push(f.strip_prefix(&src).unwrap().display().to_string());
        }
    }
    assert!(named.is_empty(), "clap named in the library: {named:?}");
}

/// Each contact law's `evaluate` names its WGSL twin (issue 42 item 1: a law and its
/// twin side by side), and the twin is a function of shaders/laws.wgsl that takes a
/// `ContactInput` and gives a `ContactOutput`, as the Rust one does.
#[test]
fn every_law_names_its_wgsl_twin_and_the_twin_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let wgsl = std::fs::read_to_string(root.join("shaders/laws.wgsl")).unwrap();
    let laws = [
        "spring_dashpot",
        "continuous",
        "overlap_area",
        "hertz_cohesive",
        "mod",
    ];
    for law in laws {
        let rust = std::fs::read_to_string(root.join(format!("src/law/{law}.rs"))).unwrap();
        let twin = (rust.lines())
            .find_map(|l| l.split("WGSL twin: `").nth(1))
            .and_then(|rest| rest.split('`').next())
            .unwrap_or_else(|| panic!("src/law/{law}.rs: `evaluate` names no WGSL twin"));
        let signature = format!("fn {twin}(c: ContactInput) -> ContactOutput {{");
        assert!(
            wgsl.contains(&signature),
            "src/law/{law}.rs names `{twin}`, which shaders/laws.wgsl lacks"
        );
        assert!(rust.contains("pub fn evaluate(&self, c: &ContactInput) -> ContactOutput"));
    }
}
