//! The scene: everything a run needs, parsed strictly from JSON and validated once.
//!
//! Parsing (`load`/`parse`) turns text into a [`Scene`]; unknown keys and wrong types are
//! errors naming the key path (serde + serde_path_to_error). [`validate`] then checks
//! values (positive radii, known materials, a time step the stiffness allows) and names
//! the offending key too. Nothing downstream re-checks user input.

mod overrides;
pub mod rows;
mod schema;
mod sizes;
mod stability;
mod strict;
mod validate;
mod walls;

pub use crate::law::spec::*;
pub use overrides::apply_override;
pub use schema::*;
pub use sizes::{
    material_of, max_diameter, polygon_of, reach_bound_of, smallest_particle_area, typical_masses,
};
pub use stability::{
    DAMPING_STABILITY, IMPACT_DAMPING_STABILITY, MIN_STEPS_PER_CONTACT,
    RECOMMENDED_STEPS_PER_CONTACT, shortest_contact_time,
};
pub use validate::validate;

/// Non-fatal remarks about a valid scene (e.g. dt above t_c/10).
pub fn warnings(scene: &Scene) -> Vec<String> {
    validate(scene).unwrap_or_default()
}

use std::path::Path;

/// The built-in default scene: a small point-source heap of disks (`talus run`).
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default_heap.json");

/// A problem with a scene, always naming the key path it concerns.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {file}: {reason}")]
    Io { file: String, reason: String },
    #[error("scene is not valid JSON: {0}")]
    Syntax(String),
    #[error("{path}: {reason}")]
    Invalid { path: String, reason: String },
}

impl From<crate::law::spec::ParamError> for SceneError {
    fn from(e: crate::law::spec::ParamError) -> Self {
        Self::Invalid {
            path: e.path,
            reason: e.reason,
        }
    }
}

impl SceneError {
    pub fn invalid(path: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid {
            path: path.into(),
            reason: reason.into(),
        }
    }
}

/// Reads a scene file, applies `--set` overrides, parses strictly and validates.
pub fn load(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
        file: path.display().to_string(),
        reason: e.to_string(),
    })?;
    parse(&text, overrides)
}

/// Parses scene text (JSON), applies `path=value` overrides, and validates the result.
pub fn parse(text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
    let mut value = strict::parse_value(text)?;
    for o in overrides {
        apply_override(&mut value, o)?;
    }
    let mut scene = from_value(value)?;
    let checked = validate::check(&scene)?;
    resolve_materials(&mut scene, &checked.law);
    Ok(scene)
}

/// Records what the material form resolved (`contact.resolved`, src/law/restitution.rs),
/// so that the run's `scene.json` says which k and γ per unit mass each pair got. Never an
/// input: a `resolved` block read back is replaced by the values computed anew.
fn resolve_materials(scene: &mut Scene, law: &crate::law::ContactLaw) {
    let names: Vec<String> = scene.materials.keys().cloned().collect();
    match (&mut scene.contact, law) {
        (ContactSpec::SpringDashpot(spec), crate::law::ContactLaw::SpringDashpot(l)) => {
            spec.resolved = l.resolved(&names);
        }
        (ContactSpec::OverlapArea(spec), crate::law::ContactLaw::OverlapArea(l)) => {
            spec.resolved = l.resolved(&names);
        }
        _ => {}
    }
}

/// Strict typed parse of a JSON value; errors carry the key path. An array where the
/// scene has an object is refused (`strict::objects_are_objects`).
pub fn from_value(value: serde_json::Value) -> Result<Scene, SceneError> {
    // serde would read a list as the scene's fields in order and name only an index
    // ("[0]: invalid type: map, expected a string"; issue 16, the fuzz in tests/hostile.rs).
    if !value.is_object() {
        let got = match value {
            serde_json::Value::Array(_) => "an array",
            serde_json::Value::String(_) => "a string",
            serde_json::Value::Number(_) => "a number",
            serde_json::Value::Bool(_) => "a boolean",
            _ => "null",
        };
        return Err(SceneError::invalid(
            "scene",
            format!("expected an object with named keys, got {got}"),
        ));
    }
    let scene = typed(&value)?;
    let back = serde_json::to_value(&scene).expect("a scene always serialises");
    strict::objects_are_objects(&value, &back, "")?;
    Ok(scene)
}

fn typed(value: &serde_json::Value) -> Result<Scene, SceneError> {
    serde_path_to_error::deserialize(value.clone()).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." {
            "scene".to_string()
        } else {
            path
        };
        refine_tagged_error(value, &path)
            .unwrap_or_else(|| SceneError::invalid(path, reason(e.into_inner())))
    })
}

fn reason(e: serde_json::Error) -> String {
    e.to_string().replace(
        "data did not match any variant of untagged enum Size",
        "expected a diameter (a number) or {\"uniform\": [min, max]}",
    )
}

/// serde buffers internally tagged enums (`"kind"`, `"law"`), which hides the key inside
/// them from the path. Re-parse such a block as its variant's struct to find the key.
fn refine_tagged_error(root: &serde_json::Value, path: &str) -> Option<SceneError> {
    use serde::de::DeserializeOwned;
    fn inner<T: DeserializeOwned>(
        mut block: serde_json::Value,
        tag: &str,
        path: &str,
    ) -> Option<SceneError> {
        block.as_object_mut()?.remove(tag);
        let e = serde_path_to_error::deserialize::<_, T>(block).err()?;
        let sub = e.path().to_string();
        let full = if sub == "." {
            path.to_string()
        } else {
            format!("{path}.{sub}")
        };
        Some(SceneError::invalid(full, reason(e.into_inner())))
    }
    if path == "contact" {
        let block = root.get("contact")?.clone();
        return match block.get("law")?.as_str()? {
            "spring_dashpot" => inner::<SpringDashpotSpec>(block, "law", path),
            "overlap_area" => inner::<OverlapAreaSpec>(block, "law", path),
            "continuous" => inner::<ContinuousSpec>(block, "law", path),
            "hooke_equivalent" => inner::<HookeEquivalentSpec>(block, "law", path),
            "hertz_cohesive" => inner::<HertzCohesiveSpec>(block, "law", path),
            _ => None,
        };
    }
    let k: usize = path
        .strip_prefix("particles[")?
        .strip_suffix(']')?
        .parse()
        .ok()?;
    let block = root.get("particles")?.get(k)?.clone();
    match block.get("kind")?.as_str()? {
        "lattice_pile" => inner::<LatticePile>(block, "kind", path),
        "row" => inner::<Row>(block, "kind", path),
        "point_source" => inner::<PointSource>(block, "kind", path),
        "list" => inner::<ParticleList>(block, "kind", path),
        _ => None,
    }
}

/// The contact law of a scene: its `contact` block with the scene's gravity, materials
/// and each material's corner count (the law's own parameters come from the block alone,
/// `ContactLaw::from_spec`).
impl crate::law::ContactLaw {
    /// The contact law of a scene.
    pub fn of_scene(scene: &Scene) -> Result<Self, SceneError> {
        let g = scene.gravity.g;
        let materials: Vec<String> = scene.materials.keys().cloned().collect();
        // Each material's corner count: its first polygon block's (0 for disks).
        let corners: Vec<u32> = (materials.iter())
            .map(|m| {
                (scene.particles.iter())
                    .filter(|c| material_of(c) == m)
                    .find_map(|c| polygon_of(c).map(|p| p.corners))
                    .unwrap_or(0)
            })
            .collect();
        Ok(Self::from_spec(
            &scene.contact,
            (g[0] * g[0] + g[1] * g[1]).sqrt(),
            &materials,
            &corners,
        )?)
    }
}
