//! `--set path=value`: change any key of a scene before it is parsed.
//!
//! The path uses dots between keys and either `.N` or `[N]` for list items
//! (`contact.mu=0.3`, `particles[1].rate=2`). The value is read as JSON and, when that
//! fails, as a plain string (`integrator=leapfrog`). Missing object keys are created, so
//! a default can be overridden; the strict parse afterwards rejects unknown ones.

use super::SceneError;
use serde_json::Value;

pub fn apply_override(root: &mut Value, assignment: &str) -> Result<(), SceneError> {
    let (path, raw) = assignment.split_once('=').ok_or_else(|| {
        SceneError::invalid(assignment, "an override must have the form path=value")
    })?;
    let path = path.trim();
    if path.is_empty() {
        // Named by the whole assignment: an empty path would make the message start
        // with a bare `:`.
        return Err(SceneError::invalid(
            assignment,
            "an override needs a key path before `=`",
        ));
    }
    let segments = split_path(path)?;
    let value: Value =
        serde_json::from_str(raw.trim()).unwrap_or_else(|_| Value::String(raw.trim().into()));

    let mut node = root;
    for (k, seg) in segments.iter().enumerate() {
        let last = k + 1 == segments.len();
        node = match seg {
            Segment::Key(key) => {
                let obj = node.as_object_mut().ok_or_else(|| {
                    SceneError::invalid(
                        path,
                        format!("cannot set key `{key}`: not inside an object"),
                    )
                })?;
                if last {
                    obj.insert(key.clone(), value);
                    return Ok(());
                }
                obj.entry(key.clone())
                    .or_insert_with(|| Value::Object(Default::default()))
            }
            Segment::Index(i) => {
                let arr = node.as_array_mut().ok_or_else(|| {
                    SceneError::invalid(path, format!("cannot index [{i}]: not a list"))
                })?;
                let len = arr.len();
                let slot = arr.get_mut(*i).ok_or_else(|| {
                    SceneError::invalid(
                        path,
                        format!("index {i} is out of range (list has {len} items)"),
                    )
                })?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
        };
    }
    Err(SceneError::invalid(assignment, "empty override path"))
}

#[derive(Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

fn split_path(path: &str) -> Result<Vec<Segment>, SceneError> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = match part.find('[') {
            Some(p) => (&part[..p], &part[p..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            match key.parse::<usize>() {
                Ok(i) => out.push(Segment::Index(i)),
                Err(_) => out.push(Segment::Key(key.to_string())),
            }
        } else if rest.is_empty() {
            return Err(SceneError::invalid(path, "empty key in override path"));
        }
        while let Some(stripped) = rest.strip_prefix('[') {
            let close = stripped
                .find(']')
                .ok_or_else(|| SceneError::invalid(path, "unclosed `[` in override path"))?;
            let i = stripped[..close]
                .parse::<usize>()
                .map_err(|_| SceneError::invalid(path, "list index must be a number"))?;
            out.push(Segment::Index(i));
            rest = &stripped[close + 1..];
        }
        if !rest.is_empty() {
            return Err(SceneError::invalid(path, "unexpected text after `]`"));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn sets_nested_keys_list_items_and_strings() {
        let mut v = json!({"contact": {"mu": 0.1}, "particles": [{"rate": 1}, {"rate": 2}]});
        apply_override(&mut v, "contact.mu=0.3").unwrap();
        apply_override(&mut v, "particles[1].rate=5").unwrap();
        apply_override(&mut v, "particles.0.rate=7").unwrap();
        apply_override(&mut v, "integrator=leapfrog").unwrap();
        assert_eq!(v["contact"]["mu"], json!(0.3));
        assert_eq!(v["particles"][1]["rate"], json!(5));
        assert_eq!(v["particles"][0]["rate"], json!(7));
        assert_eq!(v["integrator"], json!("leapfrog"));
    }

    #[test]
    fn rejects_bad_paths() {
        let mut v = json!({"particles": [{"rate": 1}]});
        assert!(apply_override(&mut v, "particles[3].rate=1").is_err());
        assert!(apply_override(&mut v, "no_equals_sign").is_err());
        assert!(apply_override(&mut v, "particles[x]=1").is_err());
        let e = apply_override(&mut v, " =1").unwrap_err().to_string();
        assert!(e.starts_with(" =1: an override needs a key path"), "{e}");
    }
}
