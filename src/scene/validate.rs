//! Value checks on a parsed scene. Each error names the key path and the reason; the
//! contact law's own parameters are checked where its coefficients are built
//! (`ContactLaw::from_spec`).

use super::sizes::{estimated_particles, material_of, polygon_of, reach_bound_of, size_bounds};
use super::{ContactSpec, Creation, PolygonSpec, Scene, SceneError, Size};
use crate::law::ContactLaw;

fn finite_positive(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be positive, got {v}"),
        ))
    }
}

fn finite_non_negative(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be zero or positive, got {v}"),
        ))
    }
}

fn material(scene: &Scene, path: &str, name: &str) -> Result<(), SceneError> {
    if scene.materials.contains_key(name) {
        Ok(())
    } else {
        let known: Vec<&str> = scene.materials.keys().map(|s| s.as_str()).collect();
        Err(SceneError::invalid(
            path,
            format!("unknown material `{name}` (defined: {})", known.join(", ")),
        ))
    }
}

fn inside(scene: &Scene, path: &str, p: [f64; 2]) -> Result<(), SceneError> {
    let d = &scene.domain;
    if p[0] >= d.x[0] && p[0] <= d.x[1] && p[1] >= d.z[0] && p[1] <= d.z[1] {
        Ok(())
    } else {
        let f = |v: f64| {
            if v.abs() < 1e6 {
                format!("{v}")
            } else {
                format!("{v:e}")
            }
        };
        Err(SceneError::invalid(
            path,
            format!("({}, {}) lies outside the domain", f(p[0]), f(p[1])),
        ))
    }
}

/// Sizes drawn by sources and layers: `diameter` or `polygon.axes`, positive ranges.
fn drawn_sizes(
    at: &dyn Fn(&str) -> String,
    diameter: Option<&Size>,
    polygon: Option<&PolygonSpec>,
) -> Result<(), SceneError> {
    let axes = polygon.and_then(|p| p.axes.as_ref());
    let sizes: Vec<(String, &Size)> = match (axes, diameter) {
        (Some(_), Some(_)) => {
            return Err(SceneError::invalid(
                at("diameter"),
                "give either diameter or polygon.axes, not both",
            ));
        }
        (None, None) => {
            return Err(SceneError::invalid(
                at("diameter"),
                "is required (or polygon.axes for polygons on ellipses)",
            ));
        }
        (Some([a, b]), None) => vec![(at("polygon.axes[0]"), a), (at("polygon.axes[1]"), b)],
        (None, Some(d)) => vec![(at("diameter"), d)],
    };
    for (path, size) in sizes {
        let (lo, hi) = size.bounds();
        if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
            return Err(SceneError::invalid(
                path,
                format!("must be positive (and lo ≤ hi for a range), got {lo}..{hi}"),
            ));
        }
    }
    Ok(())
}

/// Polygon blocks: corner counts, axes only where sizes are drawn, and the contact law
/// that goes with the shapes.
fn polygons(scene: &Scene) -> Result<(), SceneError> {
    let area_law = matches!(scene.contact, ContactSpec::OverlapArea(_));
    for (k, c) in scene.particles.iter().enumerate() {
        let at = |key: &str| format!("particles[{k}].{key}");
        match polygon_of(c) {
            Some(p) => {
                let (lo, hi) = (crate::shape::MIN_CORNERS, crate::shape::MAX_CORNERS);
                if !(lo..=hi).contains(&p.corners) {
                    return Err(SceneError::invalid(
                        at("polygon.corners"),
                        format!("must be in [{lo}, {hi}], got {}", p.corners),
                    ));
                }
                if p.axes.is_some() && !matches!(c, Creation::PointSource(_) | Creation::Layered(_))
                {
                    return Err(SceneError::invalid(
                        at("polygon.axes"),
                        "is only for point sources and layers; other blocks make regular polygons of their diameter",
                    ));
                }
                if !area_law {
                    return Err(SceneError::invalid(
                        "contact.law",
                        format!(
                            "particles[{k}] makes polygons, which need law \"overlap_area\" (paper 000 sec. 2.2)"
                        ),
                    ));
                }
            }
            // Disks under the overlap-area law meet polygons, walls and each other by
            // their overlap area too (CPU path).
            None => {}
        }
    }
    Ok(())
}

/// The most copies a scene may ask for (`replicas`).
pub const MAX_REPLICAS: u32 = 4096;

/// Checks every value; returns warnings that do not stop a run.
pub fn validate(scene: &Scene) -> Result<Vec<String>, SceneError> {
    check(scene).map(|c| c.warnings)
}

/// What checking a scene found: its contact law, built once here from the scene's
/// `contact` block (`scene::parse` records its resolved pairs with it), and the warnings.
pub(super) struct Checked {
    pub law: ContactLaw,
    pub warnings: Vec<String>,
}

/// [`validate`], keeping the law it built.
pub(super) fn check(scene: &Scene) -> Result<Checked, SceneError> {
    let mut warnings = Vec::new();
    // Without --out the name is the output folder (runs/<name>): a path in it would
    // write anywhere (issue 16).
    let n = &scene.name;
    let plain = |c: char| c.is_alphanumeric() || "-_.+".contains(c);
    if n.is_empty() || n.starts_with('.') || !n.chars().all(plain) {
        return Err(SceneError::invalid(
            "name",
            format!(
                "must be a plain name of letters, digits and - _ . + not starting with a dot \
                 (it names the output folder runs/<name>), got {n:?}"
            ),
        ));
    }
    finite_positive("dt", scene.dt)?;
    finite_positive("stop.time", scene.stop.time)?;
    finite_positive("stop.check_every", scene.stop.check_every)?;
    finite_non_negative("stop.not_before", scene.stop.not_before)?;
    if let Some(f) = scene.stop.kinetic_drop {
        finite_positive("stop.kinetic_drop", f)?;
    }
    if let Some(f) = scene.stop.kinetic_fraction {
        finite_positive("stop.kinetic_fraction", f)?;
    }
    finite_non_negative("gravity.ramp_time", scene.gravity.ramp_time)?;
    if !scene.gravity.g.iter().all(|g| g.is_finite()) {
        return Err(SceneError::invalid("gravity.g", "must be finite"));
    }
    let d = &scene.domain;
    // The width too must be finite (issue 16: [-1e308, 1e308] overflowed to infinity).
    if !(d.x[0] < d.x[1] && (d.x[1] - d.x[0]).is_finite()) {
        return Err(SceneError::invalid(
            "domain.x",
            "must be [min, max] with min < max and a finite width",
        ));
    }
    // The width too must be finite (issue 16: [-1e308, 1e308] overflowed to infinity).
    if !(d.z[0] < d.z[1] && (d.z[1] - d.z[0]).is_finite()) {
        return Err(SceneError::invalid(
            "domain.z",
            "must be [min, max] with min < max and a finite width",
        ));
    }
    // Corner counts before the estimates below, which build a layered block's polygons
    // (issue 16: `corners` 4294967295 aborted on allocation, 7·10⁶ hung; found by the
    // fuzz in tests/hostile.rs).
    polygons(scene)?;
    // Counts before anything is allocated (issue 16: a `bottom_row` of 200 000 hung, a
    // `count` of 4·10⁹ aborted on allocation).
    let limit = scene.limits.max_particles;
    if !(limit > 0.0) {
        return Err(SceneError::invalid(
            "limits.max_particles",
            "must be a positive number",
        ));
    }
    if !(1..=MAX_REPLICAS).contains(&scene.replicas) {
        return Err(SceneError::invalid(
            "replicas",
            format!(
                "must be between 1 and {MAX_REPLICAS}, got {}",
                scene.replicas
            ),
        ));
    }
    let mut total = 0.0;
    for (k, c) in scene.particles.iter().enumerate() {
        let (n, key) = estimated_particles(c);
        // Every copy creates as many.
        total += n * scene.replicas as f64;
        if total > limit {
            return Err(SceneError::invalid(
                format!("particles[{k}].{key}"),
                format!(
                    "the scene would create about {total:.3e} particles (~{:.0} GB), more \
                     than limits.max_particles = {limit:.3e}; raise limits.max_particles \
                     if you mean it",
                    total * 1e3 / 1e9
                ),
            ));
        }
    }
    if scene.materials.is_empty() {
        return Err(SceneError::invalid(
            "materials",
            "at least one material is required",
        ));
    }
    for (name, m) in &scene.materials {
        finite_positive(&format!("materials.{name}.density"), m.density)?;
        finite_positive(&format!("materials.{name}.thickness"), m.thickness)?;
    }
    for (k, w) in scene.walls.iter().enumerate() {
        if w.from == w.to || !w.from.iter().chain(&w.to).all(|v| v.is_finite()) {
            return Err(SceneError::invalid(
                format!("walls[{k}]"),
                "a wall needs two distinct finite end points",
            ));
        }
        // A wall beyond the domain touches nothing there (issue 16: one ending at 1e308
        // was inert).
        inside(scene, &format!("walls[{k}].from"), w.from)?;
        inside(scene, &format!("walls[{k}].to"), w.to)?;
        let v = w.velocity;
        if !v.iter().all(|v| v.is_finite()) {
            return Err(SceneError::invalid(
                format!("walls[{k}].velocity"),
                format!("must be finite, got {v:?}"),
            ));
        }
        // Only along the wall: the segment's own motion is `motion`.
        let t = [w.to[0] - w.from[0], w.to[1] - w.from[1]];
        let across = (t[0] * v[1] - t[1] * v[0]).abs();
        if across > 1e-9 * t[0].hypot(t[1]) * v[0].hypot(v[1]) {
            return Err(SceneError::invalid(
                format!("walls[{k}].velocity"),
                format!(
                    "{v:?} is not along the wall (from {:?} to {:?}): it is the velocity of the wall's surface (a belt, a shearing wall); a wall that moves as a whole takes \"motion\": {{\"velocity\": ...}}",
                    w.from, w.to
                ),
            ));
        }
        if let Some(m) = &w.motion {
            super::walls::wall_motion(&format!("walls[{k}].motion"), m)?;
            if scene.domain.periodic_x && (m.velocity[0] != 0.0 || m.amplitude[0] != 0.0) {
                return Err(SceneError::invalid(
                    format!("walls[{k}].motion"),
                    "moves along x in a domain periodic in x: a segment is not wrapped across the seam, so only motion along z is supported there (a surface moving along x is the wall's `velocity`)",
                ));
            }
        }
    }
    if scene.particles.is_empty() {
        return Err(SceneError::invalid(
            "particles",
            "at least one creation block is required",
        ));
    }
    for (k, c) in scene.particles.iter().enumerate() {
        let at = |key: &str| format!("particles[{k}].{key}");
        material(scene, &at("material"), material_of(c))?;
        match c {
            Creation::LatticePile(p) => {
                if p.slope != 30.0 && p.slope != 60.0 {
                    return Err(SceneError::invalid(
                        at("slope"),
                        format!("must be 30 or 60 (degrees), got {}", p.slope),
                    ));
                }
                if p.bottom_row < 2 {
                    return Err(SceneError::invalid(
                        at("bottom_row"),
                        format!("must be at least 2, got {}", p.bottom_row),
                    ));
                }
                finite_positive(&at("diameter"), p.diameter)?;
                if !(p.spacing_c > -0.5 && p.spacing_c < 1.0) {
                    return Err(SceneError::invalid(
                        at("spacing_c"),
                        format!("must be in (-0.5, 1), got {}", p.spacing_c),
                    ));
                }
                if !(p.size_disorder >= 0.0 && p.size_disorder < 1.0) {
                    return Err(SceneError::invalid(
                        at("size_disorder"),
                        format!("must be in [0, 1), got {}", p.size_disorder),
                    ));
                }
                inside(
                    scene,
                    &at("center_x"),
                    [p.center_x, p.base_z + 0.5 * p.diameter],
                )?;
            }
            Creation::Row(r) => {
                finite_positive(&at("diameter"), r.diameter)?;
                finite_positive(&at("spacing"), r.spacing)?;
                inside(scene, &at("start"), r.start)?;
                let end = [
                    r.start[0] + r.count.saturating_sub(1) as f64 * r.spacing,
                    r.start[1],
                ];
                inside(scene, &at("count"), end)?;
            }
            Creation::PointSource(s) => {
                inside(scene, &at("position"), s.position)?;
                finite_non_negative(&at("spread"), s.spread)?;
                // The outlet's whole width: a particle drawn beyond the domain would be
                // lost as it appears.
                for side in [-1.0, 1.0] {
                    inside(
                        scene,
                        &at("spread"),
                        [s.position[0] + side * s.spread, s.position[1]],
                    )?;
                }
                finite_positive(&at("rate"), s.rate)?;
                finite_non_negative(&at("start_time"), s.start_time)?;
                drawn_sizes(&at, s.diameter.as_ref(), s.polygon.as_ref())?;
            }
            Creation::Layered(s) => {
                inside(scene, &at("center_x"), [s.center_x, s.base_z])?;
                finite_positive(&at("base_width"), s.base_width)?;
                finite_positive(&at("interval"), s.interval)?;
                finite_non_negative(&at("gap"), s.gap)?;
                finite_non_negative(&at("start_time"), s.start_time)?;
                if let Some(h) = s.row_height {
                    finite_positive(&at("row_height"), h)?;
                }
                if s.rows == Some(0) {
                    return Err(SceneError::invalid(
                        at("rows"),
                        "must be at least 1 (leave it out to lay rows up to the outline)",
                    ));
                }
                if !(s.slope > 0.0 && s.slope < 90.0) {
                    return Err(SceneError::invalid(
                        at("slope"),
                        format!("must be between 0 and 90 degrees, got {}", s.slope),
                    ));
                }
                drawn_sizes(&at, s.diameter.as_ref(), s.polygon.as_ref())?;
                let d = reach_bound_of(s.diameter.as_ref(), s.polygon.as_ref());
                if s.base_width < d {
                    return Err(SceneError::invalid(
                        at("base_width"),
                        format!("{} holds no particle of size up to {d}", s.base_width),
                    ));
                }
                // The fewest rows the outline needs: rows of the given height, or
                // close-packed rows of the largest particle (measured rows of smaller or
                // settling grains take more).
                let h = s.row_height.unwrap_or(0.5 * 3f64.sqrt()) * d;
                let outline =
                    ((s.base_width - d) * s.slope.to_radians().tan() / (2.0 * h)).floor() + 1.0;
                let rows = s.rows.map_or(outline, |r| outline.min(r as f64));
                let built = s.start_time + (rows - 1.0) * s.interval;
                if scene.stop.time < built {
                    // In exponent form when huge (a `row_height` of 1e-300 asks for 10³⁰⁰ rows).
                    let (rows, built) = if rows < 1e9 {
                        (format!("{rows}"), format!("{built}"))
                    } else {
                        (format!("{rows:.3e}"), format!("{built:.3e}"))
                    };
                    warnings.push(format!(
                        "particles[{k}]: stop.time = {} ends the run before the layered pile is built: it lays at least {rows} rows, one every {} (the last at t = {built})",
                        scene.stop.time, s.interval
                    ));
                }
            }
            Creation::List(l) => {
                for (q, p) in l.particles.iter().enumerate() {
                    finite_positive(
                        &format!("particles[{k}].particles[{q}].diameter"),
                        p.diameter,
                    )?;
                    inside(
                        scene,
                        &format!("particles[{k}].particles[{q}].position"),
                        p.position,
                    )?;
                }
            }
        }
    }
    let o = &scene.output;
    finite_non_negative("output.snapshot_every", o.snapshot_every)?;
    if let Some(c) = o.checkpoint_every {
        finite_non_negative("output.checkpoint_every", c)?;
    }
    finite_non_negative("output.log_every", o.log_every)?;
    finite_positive("limits.max_overlap", scene.limits.max_overlap)?;
    finite_non_negative("limits.initial_overlap", scene.limits.initial_overlap)?;
    finite_non_negative(
        "limits.max_step_displacement",
        scene.limits.max_step_displacement,
    )?;
    if let Some(skin) = scene.skin {
        finite_non_negative("skin", skin)?;
    }

    let law = ContactLaw::of_scene(scene)?;
    spheropolygons(scene, &law)?;
    rolling(scene, &law)?;
    super::walls::wall_speeds(scene)?;
    periodic(scene, &law)?;
    warnings.extend(super::stability::time_step(scene, &law)?);
    Ok(Checked { law, warnings })
}

/// A domain periodic in x is at least three neighbour-search cells wide (range and
/// skin of its largest particle), so that a particle sees a neighbour at most once,
/// through the nearest image (`state::offset`).
fn periodic(scene: &Scene, law: &ContactLaw) -> Result<(), SceneError> {
    if !scene.domain.periodic_x {
        return Ok(());
    }
    let d = super::sizes::max_diameter(scene);
    let skin = scene.skin.unwrap_or(super::DEFAULT_SKIN * d);
    let reach = law.range_factor() * d + skin;
    let width = scene.domain.x[1] - scene.domain.x[0];
    if width < 3.0 * reach {
        return Err(SceneError::invalid(
            "domain.x",
            format!(
                "a domain periodic in x must be at least 3 neighbour cells wide, 3 × (range × largest diameter + skin) = {:.4e}; it is {width:.4e}",
                3.0 * reach
            ),
        ));
    }
    Ok(())
}

/// Rolling resistance (src/law/rolling.rs) acts at disk contacts: under the disk laws,
/// which take disks only (polygons need the overlap-area law, rods `hertz_cohesive`).
/// The spring model's keys belong to it, and its stiffness must be given where the law
/// has no one k_n to take it from; `pairs` name known materials, each pair once.
fn rolling(scene: &Scene, law: &ContactLaw) -> Result<(), SceneError> {
    use crate::law::rolling::RollingModel;
    let Some(r) = &scene.rolling else {
        return Ok(());
    };
    rolling_pairs(scene, r)?;
    for (at, r) in r.entries() {
        finite_non_negative(&format!("{at}.mu_r"), r.mu_r)?;
        if let Some(k) = r.stiffness {
            finite_positive(&format!("{at}.stiffness"), k)?;
        }
        if let Some(eta) = r.damping {
            finite_non_negative(&format!("{at}.damping"), eta)?;
        }
    }
    let name = match scene.contact {
        ContactSpec::OverlapArea(_) => Some("overlap_area"),
        ContactSpec::HertzCohesive(_) => Some("hertz_cohesive"),
        _ => None,
    };
    if let Some(name) = name {
        return Err(SceneError::invalid(
            "rolling",
            format!(
                "rolling resistance acts at disk contacts under the laws spring_dashpot, continuous and hooke_equivalent, not under \"{name}\" (polygons and rods resist rolling by their shape)"
            ),
        ));
    }
    // The keys each entry gives itself (a pair's others are the block's).
    let own = |p: Option<&crate::law::rolling::RollingPair>| match p {
        None => [("stiffness", r.stiffness), ("damping", r.damping)],
        Some(p) => [("stiffness", p.stiffness), ("damping", p.damping)],
    };
    let entries = std::iter::once(("rolling".to_string(), None)).chain(
        r.pairs
            .iter()
            .enumerate()
            .map(|(k, p)| (format!("rolling.pairs[{k}]"), Some(p))),
    );
    for (at, pair) in entries {
        match r.model {
            RollingModel::ConstantTorque => {
                for (key, given) in own(pair) {
                    if given.is_some() {
                        return Err(SceneError::invalid(
                            format!("{at}.{key}"),
                            "belongs to the model \"spring_dashpot\" (the constant torque has no spring)",
                        ));
                    }
                }
            }
            RollingModel::SpringDashpot => {
                if r.with(pair).stiffness.is_none() && law.linear_k_n().is_none() {
                    return Err(SceneError::invalid(
                        format!("{at}.stiffness"),
                        "is required here: its default, 2.25 mu_r² k_n (Ai et al. 2011), needs the law's one linear k_n (law spring_dashpot with k_n and nu = 1)",
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `rolling.pairs` name known materials (or "walls"), each unordered pair once, and not
/// walls with walls.
fn rolling_pairs(scene: &Scene, r: &crate::law::rolling::RollingSpec) -> Result<(), SceneError> {
    use crate::law::rolling::material_slot;
    use crate::law::spec::WALLS;
    let materials: Vec<String> = scene.materials.keys().cloned().collect();
    let mut seen = std::collections::BTreeSet::new();
    for (k, p) in r.pairs.iter().enumerate() {
        let at = format!("rolling.pairs[{k}].materials");
        let slot = |name: &str| {
            material_slot(&materials, name).ok_or_else(|| {
                SceneError::invalid(
                    &at,
                    format!(
                        "unknown material \"{name}\" (known: {}, and \"{WALLS}\")",
                        materials.join(", ")
                    ),
                )
            })
        };
        let (a, b) = (slot(&p.materials[0])?, slot(&p.materials[1])?);
        if a == materials.len() && b == materials.len() {
            return Err(SceneError::invalid(&at, "walls do not touch walls"));
        }
        if !seen.insert((a.min(b), a.max(b))) {
            return Err(SceneError::invalid(&at, "this pair is listed twice"));
        }
    }
    Ok(())
}

/// Rods (spheropolygons) and law `hertz_cohesive` go together (issue 15): rods need the
/// law, the law takes rods and disks (disks as point cores) but not polygons, and its
/// cohesion range must lie within the neighbour search's margin.
fn spheropolygons(scene: &Scene, law: &ContactLaw) -> Result<(), SceneError> {
    let hertz = matches!(law, ContactLaw::HertzCohesive(_));
    for (k, c) in scene.particles.iter().enumerate() {
        let rod = match c {
            Creation::List(l) => l.rod.as_ref(),
            Creation::PointSource(p) => p.rod.as_ref(),
            _ => None,
        };
        if let Creation::PointSource(p) = c {
            finite_non_negative(
                &format!("particles[{k}].velocity_spread"),
                p.velocity_spread,
            )?;
            if p.velocity_spread > 0.0 && p.rod.is_none() {
                return Err(SceneError::invalid(
                    format!("particles[{k}].velocity_spread"),
                    "applies to rods only (sources of disks and polygons pour at `velocity`)",
                ));
            }
        }
        if let Some(r) = rod {
            if !hertz {
                return Err(SceneError::invalid(
                    format!("particles[{k}].rod"),
                    "rods need \"law\": \"hertz_cohesive\" (paper 004) in the contact block",
                ));
            }
            if !(r.aspect.is_finite() && r.aspect >= 1.0) {
                return Err(SceneError::invalid(
                    format!("particles[{k}].rod.aspect"),
                    format!("must be a number ≥ 1 (length over width), got {}", r.aspect),
                ));
            }
            if polygon_of(c).is_some() {
                return Err(SceneError::invalid(
                    format!("particles[{k}].rod"),
                    "a block makes rods or polygons, not both",
                ));
            }
        }
        if hertz && polygon_of(c).is_some() {
            return Err(SceneError::invalid(
                format!("particles[{k}].polygon"),
                "law hertz_cohesive takes rods and disks; polygons need law overlap_area",
            ));
        }
        if hertz && !matches!(c, Creation::List(_) | Creation::PointSource(_)) {
            return Err(SceneError::invalid(
                format!("particles[{k}]"),
                "law hertz_cohesive takes particles from lists and point sources so far (issue 15)",
            ));
        }
    }
    if let ContactLaw::HertzCohesive(l) = law {
        let smallest = (scene.particles.iter())
            .map(|c| size_bounds(c).0)
            .fold(f64::INFINITY, f64::min);
        let limit = crate::law::hertz_cohesive::RANGE_MARGIN * smallest;
        if l.d_c > limit {
            return Err(SceneError::invalid(
                "contact.d_c",
                format!(
                    "{} is beyond the neighbour search's margin: at most {:.1e} of the smallest particle's diameter, {limit:.3e} here",
                    l.d_c,
                    crate::law::hertz_cohesive::RANGE_MARGIN
                ),
            ));
        }
    }
    Ok(())
}
