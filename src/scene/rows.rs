//! The rows a layered block (paper 000 sec. 5.4.2, `create::layered`) lays, from its
//! spec alone: the largest reach d_max, each row's height and width, and how many rows
//! there are at most. The scene's checks and the creators read them alike.

use super::Layered;

/// d_max: the largest particle's reach (circumscribed diameter).
pub fn largest(spec: &Layered) -> f64 {
    super::reach_bound_of(spec.diameter.as_ref(), spec.polygon.as_ref())
}

/// Height of a row: the fixed `row_height`, or a close-packed row of the largest
/// particles, (√3/2) d_max.
fn row_height(spec: &Layered) -> f64 {
    spec.row_height.unwrap_or(0.5 * 3f64.sqrt()) * largest(spec)
}

/// Width of row k with fixed rows.
pub fn row_width(spec: &Layered, k: u32) -> f64 {
    spec.base_width - 2.0 * k as f64 * row_height(spec) / spec.slope.to_radians().tan()
}

/// Rows of fixed height until one would be narrower than a particle.
fn fixed_row_count(spec: &Layered) -> u32 {
    let d = largest(spec);
    (0..100_000)
        .take_while(|&k| row_width(spec, k) >= d)
        .count() as u32
}

/// The most rows the block lays: all of them with fixed rows; with measured rows, as
/// many as a pile rising by a quarter of a close-packed row per row would need (a pile
/// that rises less, because its grains flow away, is left unfinished there); never more
/// than `rows`.
pub fn max_rows(spec: &Layered) -> u32 {
    let outline = if spec.row_height.is_some() {
        fixed_row_count(spec)
    } else {
        4 * fixed_row_count(spec)
    };
    spec.rows.map_or(outline, |r| r.min(outline))
}
