//! Mutations of valid scenes for the fuzz in tests/hostile.rs (issue 16 item 6): on the
//! JSON value (types, extreme numbers, keys deleted, added or misplaced, nesting, sizes,
//! swaps, blocks grafted from other scenes), on the text (a key twice, cuts, numbers
//! JSON or f64 cannot hold, stray characters, nesting past the parser's limit) and as
//! `--set` overrides. Every choice comes from the seeded `Rng`, so a case replays.

use serde_json::{Value, json};
use talus::base::rng::Rng;

pub fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

pub fn pick<'a, T>(rng: &mut Rng, items: &'a [T]) -> &'a T {
    &items[below(rng, items.len())]
}

#[derive(Clone, Debug, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// Every node's path, the root's (empty) first.
pub fn paths(v: &Value, at: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    out.push(at.clone());
    match v {
        Value::Object(m) => {
            for (k, w) in m {
                at.push(Seg::Key(k.clone()));
                paths(w, at, out);
                at.pop();
            }
        }
        Value::Array(a) => {
            for (k, w) in a.iter().enumerate() {
                at.push(Seg::Index(k));
                paths(w, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

pub fn node<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
    path.iter().try_fold(v, |v, s| match s {
        Seg::Key(k) => v.get(k.as_str()),
        Seg::Index(i) => v.get(*i),
    })
}

pub fn node_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, s| match s {
        Seg::Key(k) => v.get_mut(k.as_str()),
        Seg::Index(i) => v.get_mut(*i),
    })
}

/// `limits.max_particles` and its block are never mutated: the seeds set the limit low,
/// so that mutated counts are refused before anything is allocated, and raising it is
/// the user's consent to a large scene, not a hostile input.
pub fn protected(path: &[Seg]) -> bool {
    matches!(path.first(), Some(Seg::Key(k)) if k == "limits")
        && path
            .get(1)
            .is_none_or(|s| *s == Seg::Key("max_particles".into()))
}

/// Numbers at the edges: zero, negative, huge, tiny, past u32 and u64, not integers.
pub fn extreme(rng: &mut Rng) -> Value {
    pick(
        rng,
        &[
            json!(0),
            json!(-1),
            json!(1),
            json!(2),
            json!(3),
            json!(0.5),
            json!(-0.0),
            json!(30),
            json!(60),
            json!(90),
            json!(1e308),
            json!(-1e308),
            json!(1e-308),
            json!(5e-324),
            json!(4294967295u64),
            json!(4294967296u64),
            json!(u64::MAX),
            json!(i64::MIN),
            json!(1e20),
            json!(-1e20),
            json!(9007199254740993u64),
        ],
    )
    .clone()
}

/// The number times a factor (an integer stays one where it can: counts, seeds,
/// corners).
pub fn scaled(rng: &mut Rng, v: &Value) -> Value {
    let x = v.as_f64().unwrap_or(1.0);
    let scale: f64 = *pick(
        rng,
        &[-1.0, 0.0, 0.5, 2.0, 10.0, 1e3, 1e-3, 1e6, 1e-9, 1e100],
    );
    match v.as_u64() {
        Some(u) if scale >= 0.0 && scale.fract() == 0.0 && scale < 1e19 => {
            json!(u.saturating_mul(scale as u64))
        }
        _ => json!(x * scale),
    }
}

/// Values a hostile scene puts anywhere: every JSON type, extreme and special numbers,
/// strings that look like numbers, names and paths, and shapes of the scene's blocks.
pub fn palette(rng: &mut Rng) -> Value {
    match below(rng, 4) {
        0 | 1 => extreme(rng),
        2 => pick(
            rng,
            &[
                json!(null),
                json!(true),
                json!(false),
                json!(""),
                json!("x"),
                json!("0.5"),
                json!("1e308"),
                json!("grain"),
                json!("m"),
                json!("../../escape"),
                json!("spring_dashpot"),
                json!("overlap_area"),
                json!("hertz_cohesive"),
                json!("continuous"),
                json!("point_source"),
                json!("lattice_pile"),
                json!("layered"),
                json!("list"),
                json!("row"),
                json!("leapfrog"),
                json!("\u{0}\u{ffff}"),
            ],
        )
        .clone(),
        _ => pick(
            rng,
            &[
                json!([]),
                json!({}),
                json!([0, 0]),
                json!([1, 2]),
                json!([1, 0]),
                json!([1e308, -1e308]),
                json!([-1e308, 1e308]),
                json!([0.0, 1.0, 2.0]),
                json!({ "uniform": [1.0, 0.5] }),
                json!({ "uniform": [0.5, 1.5] }),
                json!({ "uniform": [0.0, 1e308] }),
                json!({ "corners": 4294967295u64, "axes": [1.0, 1.0] }),
                json!({ "corners": 6, "axes": [{ "uniform": [0.5, 1e300] }, 1.0] }),
                json!({ "corners": 5, "irregular": true }),
                json!({ "aspect": 1e308 }),
                json!({ "aspect": 3.0 }),
                json!([{ "from": [0, 0], "to": [0, 0] }]),
                json!({ "position": [0, 0], "diameter": 1e-308 }),
            ],
        )
        .clone(),
    }
}

/// The value in another type, or made larger, smaller or negative.
pub fn retyped(rng: &mut Rng, v: &Value) -> Value {
    match v {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            match below(rng, 5) {
                0 => json!(x.to_string()),
                1 => json!(x != 0.0),
                2 => json!([x]),
                _ => scaled(rng, v),
            }
        }
        Value::String(s) => match below(rng, 3) {
            0 => s.parse::<f64>().map_or(json!(1), |x| json!(x)),
            1 => json!(format!("{s}{s}")),
            _ => json!([s]),
        },
        Value::Bool(b) => pick(rng, &[json!(!b), json!(*b as u8), json!(b.to_string())]).clone(),
        Value::Null => pick(rng, &[json!(0), json!(""), json!({})]).clone(),
        Value::Array(a) => match below(rng, 2) {
            0 => Value::Object(
                a.iter()
                    .enumerate()
                    .map(|(k, v)| (k.to_string(), v.clone()))
                    .collect(),
            ),
            _ => a.first().cloned().unwrap_or(Value::Null),
        },
        Value::Object(m) => match below(rng, 2) {
            0 => Value::Array(m.values().cloned().collect()),
            _ => json!(m.len()),
        },
    }
}

/// Every key name of the seeds: a known key put where it does not belong (or where it
/// is optional) tests more than a made-up one.
pub fn key_names(seeds: &[(String, Value)]) -> Vec<String> {
    let mut keys = vec![
        "zz_unknown".to_string(),
        "skin".into(),
        "polygon".into(),
        "rod".into(),
    ];
    for (_, v) in seeds {
        let mut all = Vec::new();
        paths(v, &mut Vec::new(), &mut all);
        for p in all {
            if let Some(Seg::Key(k)) = p.last()
                && !keys.contains(k)
            {
                keys.push(k.clone());
            }
        }
    }
    keys
}

/// One structural mutation of the scene value; returns what it did.
pub fn mutate(v: &mut Value, seeds: &[(String, Value)], keys: &[String], rng: &mut Rng) -> String {
    let mut all = Vec::new();
    paths(v, &mut Vec::new(), &mut all);
    all.retain(|p| !protected(p));
    // Numbers are where most of the checks are: a third of the mutations change one,
    // to an extreme or by a factor, and leave the scene's shape alone.
    let numbers: Vec<&Vec<Seg>> = (all.iter())
        .filter(|p| node(v, p).is_some_and(|n| n.is_number()))
        .collect();
    if !numbers.is_empty() && below(rng, 3) == 0 {
        let path = (*pick(rng, &numbers)).clone();
        let node = node_mut(v, &path).unwrap();
        *node = if below(rng, 2) == 0 {
            extreme(rng)
        } else {
            scaled(rng, node)
        };
        return format!("{path:?} = {node}");
    }
    let path = pick(rng, &all).clone();
    let show = format!("{path:?}");
    match below(rng, 9) {
        0 => {
            let new = palette(rng);
            let s = format!("{show} = {new}");
            *node_mut(v, &path).unwrap() = new;
            s
        }
        1 | 2 => {
            let node = node_mut(v, &path).unwrap();
            *node = retyped(rng, node);
            format!("{show} retyped to {node}")
        }
        3 => {
            // Delete the key or list item (the root is emptied).
            let Some((last, parent)) = path.split_last() else {
                *v = json!({});
                return "root emptied".into();
            };
            match (node_mut(v, parent).unwrap(), last) {
                (Value::Object(m), Seg::Key(k)) => drop(m.remove(k)),
                (Value::Array(a), Seg::Index(i)) => drop(a.remove(*i)),
                _ => unreachable!(),
            }
            format!("{show} deleted")
        }
        4 => {
            // A key added to the nearest object at or above the path (not the limit's,
            // see `protected`).
            let key = pick(rng, keys).clone();
            if key == "limits" || key == "max_particles" {
                return format!("{show}: {key} not added");
            }
            let new = if below(rng, 2) == 0 {
                palette(rng)
            } else {
                graft(rng, seeds, &key)
            };
            let s = format!("{show} gets {key} = {new}");
            let mut at = path.clone();
            loop {
                if let Some(Value::Object(m)) = node_mut(v, &at) {
                    m.insert(key, new);
                    return s;
                }
                if at.pop().is_none() {
                    return format!("{show}: no object to add {key} to");
                }
            }
        }
        5 => {
            let node = node_mut(v, &path).unwrap();
            let inner = node.take();
            *node = if below(rng, 2) == 0 {
                json!([inner])
            } else {
                json!({ "value": inner })
            };
            format!("{show} wrapped")
        }
        6 => {
            // Sizes: a list grown, cut or reversed; an object emptied.
            let node = node_mut(v, &path).unwrap();
            match &mut *node {
                Value::Array(a) if !a.is_empty() => match below(rng, 4) {
                    0 => {
                        let item = pick(rng, a).clone();
                        let more = *pick(rng, &[1, 10, 1000]);
                        a.extend(std::iter::repeat_n(item, more));
                    }
                    1 => a.clear(),
                    2 => drop(a.pop()),
                    _ => a.reverse(),
                },
                Value::Object(m) => m.clear(),
                other => *other = palette(rng),
            }
            format!("{show} resized to {node}")
        }
        7 => {
            // Two values swapped (neither inside the other).
            let other = pick(rng, &all).clone();
            let nested = |a: &[Seg], b: &[Seg]| a.len() <= b.len() && b[..a.len()] == *a;
            if nested(&path, &other) || nested(&other, &path) {
                return format!("{show} swap skipped");
            }
            let a = node_mut(v, &path).unwrap().take();
            let b = std::mem::replace(node_mut(v, &other).unwrap(), a);
            *node_mut(v, &path).unwrap() = b;
            format!("{show} swapped with {other:?}")
        }
        _ => {
            // The same key's value from another seed (a law, a block, a size).
            let Some(Seg::Key(key)) = path.last() else {
                return format!("{show} graft skipped");
            };
            let new = graft(rng, seeds, key);
            let s = format!("{show} = {new} (grafted)");
            *node_mut(v, &path).unwrap() = new;
            s
        }
    }
}

/// The value of `key` somewhere in a random seed (or a palette value if none has it).
pub fn graft(rng: &mut Rng, seeds: &[(String, Value)], key: &str) -> Value {
    let (_, seed) = pick(rng, seeds);
    let mut all = Vec::new();
    paths(seed, &mut Vec::new(), &mut all);
    all.retain(|p| p.last() == Some(&Seg::Key(key.to_string())));
    if all.is_empty() {
        return palette(rng);
    }
    let mut s = seed.clone();
    let path = pick(rng, &all).clone();
    node_mut(&mut s, &path).unwrap().take()
}

/// Byte positions in `text` just before `"key":`, with the key.
pub fn key_positions(text: &str) -> Vec<(usize, String)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut k = 0;
    while let Some(off) = text[k..].find("\":") {
        let end = k + off;
        if let Some(start) = text[..end].rfind('"')
            && b[start + 1..end]
                .iter()
                .all(|c| c.is_ascii_alphanumeric() || *c == b'_')
        {
            out.push((start, text[start + 1..end].to_string()));
        }
        k = end + 2;
    }
    out
}

/// A mutation of the text that a JSON value cannot hold: a key twice, a cut, a number
/// JSON or f64 cannot represent, a stray character.
pub fn mutate_text(text: &mut String, rng: &mut Rng) -> String {
    match below(rng, 4) {
        0 => {
            let keys = key_positions(text);
            if keys.is_empty() {
                return "no key to repeat".into();
            }
            let (at, key) = pick(rng, &keys).clone();
            let dup = format!("\"{key}\":{},", palette(rng));
            text.insert_str(at, &dup);
            format!("key {key} twice at byte {at}")
        }
        1 => {
            let at = text.floor_char_boundary(below(rng, text.len().max(1)));
            text.truncate(at);
            format!("cut at byte {at}")
        }
        2 => {
            // A number (not the particle limit, see `protected`) written in a way JSON
            // does not allow, or out of f64's range, or nested past serde_json's
            // recursion limit of 128.
            let numbers: Vec<usize> = text
                .char_indices()
                .filter(|&(k, c)| {
                    (c.is_ascii_digit() || c == '-')
                        && text[..k].ends_with([':', '[', ','])
                        && !text[..k].ends_with("\"max_particles\":")
                })
                .map(|(k, _)| k)
                .collect();
            let Some(&at) = numbers.get(below(rng, numbers.len().max(1))) else {
                return "no number".into();
            };
            let end = text[at..]
                .find([',', ']', '}'])
                .map_or(text.len(), |e| at + e);
            const WRITTEN: &[&str] = &[
                "1e999",
                "-1e999",
                "1e-999",
                "NaN",
                "Infinity",
                "-Infinity",
                "01",
                "0x1F",
                "1.e5",
                ".5",
                "-",
                "+1",
                "99999999999999999999999",
                "-99999999999999999999",
                "1e",
                "\"1\"",
                "nul",
            ];
            let new = match below(rng, WRITTEN.len() + 1) {
                k if k < WRITTEN.len() => WRITTEN[k].to_string(),
                _ => {
                    let depth = *pick(rng, &[127, 128, 100_000]);
                    format!("{}1{}", "[".repeat(depth), "]".repeat(depth))
                }
            };
            text.replace_range(at..end, &new);
            format!("number at byte {at} = {}", &new[..new.len().min(20)])
        }
        _ => {
            let at = text.floor_char_boundary(below(rng, text.len().max(1)));
            let c = *pick(
                rng,
                &[
                    '{', '}', '[', ']', ',', ':', '"', '0', '9', 'e', '-', ' ', '\\', 'é',
                ],
            );
            let end = text[at..]
                .chars()
                .next()
                .map_or(at, |ch| at + ch.len_utf8());
            text.replace_range(at..end, &c.to_string());
            format!("byte {at} = {c:?}")
        }
    }
}

/// A `--set` override: a path of the scene (with `.N` or `[N]` for list items) or a
/// broken one, and a value.
pub fn override_text(v: &Value, rng: &mut Rng) -> String {
    let mut all = Vec::new();
    paths(v, &mut Vec::new(), &mut all);
    all.retain(|p| !p.is_empty() && !protected(p));
    let path = pick(rng, &all);
    let dots = below(rng, 2) == 0;
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) if s.is_empty() => s.push_str(k),
            Seg::Key(k) => s.push_str(&format!(".{k}")),
            Seg::Index(i) if dots => s.push_str(&format!(".{i}")),
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    let value = match below(rng, 3) {
        0 => palette(rng).to_string(),
        1 => pick(rng, &["", "small", "[1,", "{", "1e999", "NaN", "=", "null"]).to_string(),
        _ => retyped(rng, node(v, path).unwrap()).to_string(),
    };
    match below(rng, 12) {
        0 => pick(
            rng,
            &[
                "no_equals_sign".to_string(),
                format!("{s}..x={value}"),
                format!("{s}[={value}"),
                format!("{s}[99999999999999999999]={value}"),
                format!("{s}[1]x={value}"),
                format!("={value}"),
                format!("{s}.new_key.deeper={value}"),
            ],
        )
        .clone(),
        _ => format!("{s}={value}"),
    }
}
