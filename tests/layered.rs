//! Layer-by-layer construction (paper 000 sec. 5.4.2): rows narrowing with the outline,
//! dropped gently onto the pile.

mod common;
use common::*;
use serde_json::json;

#[test]
fn rows_narrow_with_the_outline_and_land_gently() {
    for polygons in [false, true] {
        let mut s = sim(&layered_pile(polygons));
        // Row k is 16 − 3k wide (h = (√3/2) d, tan 30°): 16, 13, 10, 7, 4, 1 particles.
        let mut worst: f64 = 0.0;
        let mut counts = Vec::new();
        for _ in 0..(12.0 / 0.002) as usize {
            let before = s.particles.len();
            s.step().unwrap();
            if s.particles.len() > before {
                counts.push(s.particles.len() - before);
            }
            for c in &s.contacts {
                worst = worst.max(c.overlap);
            }
        }
        assert_eq!(
            counts,
            vec![16, 13, 10, 7, 4, 1],
            "polygons {polygons}: rows"
        );
        assert!(s.feeding_done(), "all rows laid");
        assert_eq!(s.lost, 0);
        // Dropped from 0.3 d: no violent impacts, overlaps stay small.
        assert!(worst < 0.02, "polygons {polygons}: largest overlap {worst}");
        // The top particle sits on the centre line, about five rows up.
        let top = (0..s.particles.len())
            .max_by(|&a, &b| s.particles.q[0][a][1].total_cmp(&s.particles.q[0][b][1]))
            .unwrap();
        let [x, z] = s.particles.position(top);
        assert!(x.abs() < 1.5, "polygons {polygons}: top at x = {x}");
        assert!(z > 3.5 && z < 6.0, "polygons {polygons}: top at z = {z}");
    }
}

#[test]
fn layered_blocks_with_point_sources_are_refused_by_the_gpu_path_with_a_reason() {
    // The GPU path lays rows from the host and pours sources on the device; within one
    // step their order would differ from the CPU path's, so the mix is refused.
    let mut v = layered_pile(false);
    v["particles"].as_array_mut().unwrap().push(json!({
        "kind": "point_source", "material": "m", "position": [0.0, 10.0], "rate": 1.0,
        "count": 3, "diameter": 1.0 }));
    let s = sim(&v);
    let Some(gpu) = common::gpu("layered_blocks_with_point_sources_are_refused") else {
        return;
    };
    let err = talus::gpu::GpuSimulation::with_gpu(s, gpu)
        .err()
        .expect("refused");
    assert!(err.to_string().contains("layer-by-layer"), "{err}");
}
