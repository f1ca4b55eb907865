//! `cargo bench --bench backends`: the `talus bench` workloads (settled packings of 10³,
//! 10⁴ and 10⁵ disks, lattice piles of 10³, 10⁴ and 5·10⁴ 12-gons, and the reduced R4
//! pour) on the CPU and GPU paths, as JSON.
//! Set TALUS_BENCH_SIZES=1000,10000 to choose sizes.

use talus::gpu::device::BackendChoice;

fn main() {
    let sizes: Vec<usize> = std::env::var("TALUS_BENCH_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1000, 10_000, 100_000]);
    let mut backends = vec![BackendChoice::Cpu];
    if talus::gpu::device::choose_adapter().is_ok() {
        backends.push(BackendChoice::Gpu);
    } else {
        eprintln!("no GPU adapter: measuring the CPU path only");
    }
    let polygon_sizes = vec![1000, 10_000, 50_000];
    match talus::bench::run(
        &backends,
        &sizes,
        &polygon_sizes,
        &[1000, 6000],
        talus::bench::Timing {
            steps: 200,
            budget: None,
            pour: true,
            kernels: false,
        },
        &mut |l| eprintln!("{l}"),
        &mut |_| {},
    ) {
        Ok(r) => println!("{}", serde_json::to_string_pretty(&r).unwrap()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
