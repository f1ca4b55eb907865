//! Strict JSON for scenes (issue 16 item 2): a key twice in one object is an error naming
//! its path (serde_json keeps the last one silently, so `"dt": 5.0, "dt": 0.002` ran with
//! the second), and an array where the scene has an object is an error too (serde reads a
//! struct from an array as its fields in order, so `"stop": [4.0, 0.5]` set
//! `stop.time` and the next field).

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};

use super::SceneError;

/// Parses JSON text into a value, refusing duplicate keys.
pub fn parse_value(text: &str) -> Result<Value, SceneError> {
    let mut d = serde_json::Deserializer::from_str(text);
    let v = Seed {
        path: String::new(),
    }
    .deserialize(&mut d)
    .and_then(|v| d.end().map(|_| v))
    .map_err(|e| SceneError::Syntax(e.to_string()))?;
    Ok(v)
}

/// Where the typed scene (serialised back) has an object, the input must have one: the
/// first array found there is an error naming its path.
pub fn objects_are_objects(input: &Value, typed: &Value, path: &str) -> Result<(), SceneError> {
    match (input, typed) {
        (Value::Array(_), Value::Object(_)) => Err(SceneError::invalid(
            if path.is_empty() { "scene" } else { path },
            "expected an object with named keys, got an array",
        )),
        (Value::Object(a), Value::Object(b)) => {
            for (k, v) in a {
                if let Some(w) = b.get(k) {
                    objects_are_objects(v, w, &join(path, k))?;
                }
            }
            Ok(())
        }
        (Value::Array(a), Value::Array(b)) => {
            for (k, (v, w)) in a.iter().zip(b).enumerate() {
                objects_are_objects(v, w, &format!("{path}[{k}]"))?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// A JSON value at `path`.
struct Seed {
    path: String,
}

impl<'de> DeserializeSeed<'de> for Seed {
    type Value = Value;

    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Seed {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        serde_json::Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| E::custom(format!("{}: not a finite number", self.path)))
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }

    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(v) = seq.next_element_seed(Seed {
            path: format!("{}[{}]", self.path, out.len()),
        })? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = join(&self.path, &key);
            if out.contains_key(&key) {
                return Err(de::Error::custom(format!(
                    "{path}: the key appears twice (one of the values would be ignored)"
                )));
            }
            let v = map.next_value_seed(Seed { path })?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_duplicate_key_is_named_with_its_path() {
        let e = parse_value(r#"{"contact": {"k_n": 1, "mu": 0.5, "k_n": 2}}"#).unwrap_err();
        assert!(
            e.to_string().contains("contact.k_n: the key appears twice"),
            "{e}"
        );
        let e = parse_value(r#"{"walls": [{"from": [0, 0]}, {"to": 1, "to": 2}]}"#).unwrap_err();
        assert!(e.to_string().contains("walls[1].to"), "{e}");
        // The same key in two objects is fine, and numbers keep their kind.
        let v = parse_value(r#"{"a": {"x": 1}, "b": {"x": 2.5}, "c": [1, -2]}"#).unwrap();
        assert_eq!(v["a"]["x"], serde_json::json!(1));
        assert_eq!(v["b"]["x"], serde_json::json!(2.5));
        assert_eq!(v["c"], serde_json::json!([1, -2]));
        assert!(parse_value("{} x").is_err(), "trailing characters");
    }

    #[test]
    fn an_array_where_an_object_belongs_is_named() {
        let input = serde_json::json!({ "stop": [4.0, 0.5], "g": [0.0, 1.0] });
        let typed = serde_json::json!({ "stop": { "time": 4.0 }, "g": [0.0, 1.0] });
        let e = objects_are_objects(&input, &typed, "").unwrap_err();
        assert!(e.to_string().starts_with("stop: expected an object"), "{e}");
        let fine = serde_json::json!({ "stop": { "time": 4.0 }, "g": [0.0, 1.0] });
        assert!(objects_are_objects(&fine, &typed, "").is_ok());
    }
}
