//! The numbers the papers report for R1–R9 that a picture can show beside talus's own
//! (issue 40 item 5), each with where it stands in its paper (`../shared/seeds/`).

use crate::render::{PaperMarks, PaperNumber};

/// The angle of repose the paper reports for a variant of reproduction `id`, in
/// degrees; a seed's variant (`pour-seed3`) has its setting's.
pub fn repose_deg(id: &str, variant: &str) -> Option<PaperNumber> {
    let setting = variant.split("-seed").next().unwrap_or(variant);
    let number = |value: f64, spread: Option<f64>, source: &str| PaperNumber {
        value,
        spread,
        source: source.into(),
    };
    match (id, setting) {
        // Paper 001 on its Fig. 1 (1334 disks, n = 36): "35° ± 5°".
        ("R4", _) => Some(number(35.0, Some(5.0), "paper 001 (Fig. 1)")),
        // Paper 001 on Fig. 6(a): n = 144 with r0 = 1.047σ gives 35° "as opposed to 31°
        // for the n = 36 case" (talus's `n144` keeps R4's tail: no number of the paper's).
        ("R5", "continuous-n36") => Some(number(31.0, None, "paper 001 (n = 36)")),
        ("R5", "n144-short") => Some(number(35.0, None, "paper 001 (n = 144)")),
        // Paper 000 Table 2: the slopes of the wedge and layered heaps.
        ("R7", "wedge-mono") => Some(number(23.0, None, "paper 000 (Table 2)")),
        ("R7", "wedge-medium") => Some(number(24.0, None, "paper 000 (Table 2)")),
        ("R7", "wedge-poly") => Some(number(28.0, None, "paper 000 (Table 2)")),
        ("R7", "layered-medium" | "layered-free") => {
            Some(number(32.0, None, "paper 000 (Table 2)"))
        }
        _ => None,
    }
}

/// The papers' numbers that the pictures of a variant draw.
pub fn marks(id: &str, variant: &str) -> PaperMarks {
    PaperMarks {
        repose_deg: repose_deg(id, variant),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_heap_reproduction_has_its_papers_angle_and_the_lattices_none() {
        assert_eq!(repose_deg("R4", "pour-seed3").unwrap().value, 35.0);
        assert_eq!(repose_deg("R5", "continuous-n36").unwrap().value, 31.0);
        assert_eq!(repose_deg("R5", "n144-short").unwrap().value, 35.0);
        assert!(repose_deg("R5", "n144").is_none());
        assert_eq!(repose_deg("R7", "layered-medium").unwrap().value, 32.0);
        assert_eq!(
            repose_deg("R4", "pour").unwrap().label(),
            "paper 001 (Fig. 1): 35 ± 5"
        );
        // The lattice piles are 30° by construction: no reported angle to compare.
        assert!(repose_deg("R1", "nu-1").is_none() && repose_deg("R8", "mu-0.3").is_none());
    }
}
