//! `talus check`: a scene validated and described without running it, whether it fits
//! the GPU (`--backend gpu`), and its run time estimated (`--estimate`).

use super::build_simulation;
use super::choices::Backend;
use super::failure::Failure;
use std::path::PathBuf;
use talus::gpu::device;
use talus::gpu::{GpuError, GpuSimulation};
use talus::run::Engine;
use talus::{io::checkpoint, run, scene, sim::Simulation};

pub(super) fn cmd_check(
    path: Option<PathBuf>,
    overrides: Vec<String>,
    estimate: bool,
    backend: Option<Backend>,
) -> Result<(), Failure> {
    let sim = build_simulation(&path, &overrides)?;
    out!(
        "scene `{}`: {} particles at start ({} fixed), {} steps of dt = {}",
        sim.scene.name,
        sim.particles.len(),
        sim.particles.len() - sim.particles.mobile_count(),
        run::total_steps(&sim),
        sim.dt()
    );
    for line in what_creators_add(&sim) {
        out!("{line}");
    }
    let names: Vec<String> = sim.scene.materials.keys().cloned().collect();
    let lines = match &sim.law {
        talus::law::ContactLaw::SpringDashpot(l) => {
            let masses = scene::typical_masses(&sim.scene);
            l.describe(&names, &masses)
        }
        talus::law::ContactLaw::OverlapArea(l) => l.describe(&names),
        _ => Vec::new(),
    };
    for line in lines {
        out!("{line}");
    }
    let d = &sim.scene.domain;
    if d.periodic_x {
        out!(
            "domain periodic in x (domain.periodic_x): period {} from x = {} to {}; particles leave through one side and come back through the other, and touch across the seam",
            d.period_x(),
            d.x[0],
            d.x[1]
        );
    }
    for (k, w) in sim.scene.walls.iter().enumerate() {
        let v = w.velocity;
        if v[0] != 0.0 || v[1] != 0.0 {
            out!(
                "wall {k}: its surface moves along it at ({}, {}) (walls[{k}].velocity)",
                v[0],
                v[1]
            );
        }
        if let Some(m) = w.motion {
            let period = m.period.filter(|_| m.omega() != 0.0);
            out!(
                "wall {k}: the segment moves by v t + A sin(2π t / T) (walls[{k}].motion), v = ({}, {}), A = ({}, {}), T = {}; top speed {:.4e}; the neighbour lists are rebuilt once it has moved by half the skin",
                m.velocity[0],
                m.velocity[1],
                m.amplitude[0],
                m.amplitude[1],
                period.map_or("none".to_string(), |p| p.to_string()),
                m.top_speed()
            );
        }
    }
    for line in sim.rolling.describe(&names) {
        out!("{line}");
    }
    if backend == Some(Backend::Gpu) {
        check_gpu_fit(&sim)?;
    }
    if estimate {
        estimate_run_time(sim, backend.unwrap_or(Backend::Auto))?;
    }
    Ok(())
}

/// `talus check --backend gpu`: whether the scene fits the adapter a GPU run would take,
/// with everything its sources and layered rows will add (`gpu::footprint`), before a
/// run finds out at its upload.
fn check_gpu_fit(sim: &Simulation) -> Result<(), Failure> {
    if let Some(reason) = talus::gpu::unsupported(sim) {
        return Err(Failure::failed(format!(
            "--backend gpu: {reason}; use --backend cpu"
        )));
    }
    let adapter = device::choose_adapter().map_err(GpuError::from)?;
    let name = adapter.get_info().name;
    let binding = device::binding_limit(&adapter.limits());
    let needs = talus::gpu::footprint(sim);
    let (what, bytes) = needs.buffers[0];
    let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
    out!(
        "GPU path on {name}: {} particles at most (those there are and those to come), {} \
         candidates each, a {} × {} cell grid; the largest buffer, {what}, takes {:.1} MiB \
         of the {:.0} MiB one binding holds",
        needs.particles,
        needs.list_cap,
        needs.grid[0],
        needs.grid[1],
        mib(bytes),
        mib(binding)
    );
    match needs.misfit(binding) {
        None => {
            out!("the scene fits {name}");
            Ok(())
        }
        Some(why) => Err(Failure::failed(format!(
            "the scene does not fit {name}: {why}; use --backend cpu"
        ))),
    }
}

/// `talus check --estimate`: the expected work of the run, and the time it takes on each
/// backend. A scene without point sources is timed as it stands, for a few seconds. A
/// pour is timed on stand-ins for its grown heap at three sizes up to its final count
/// (`run::estimate::grown_pile`), and each stretch of the run's expected work is
/// divided by the rate at its size: timed from its start alone, where a few falling
/// grains cost less per particle than the heap they grow into, the 50 000-polygon heap
/// came out 6–7× low (issue 37 item 7).
fn estimate_run_time(sim: Simulation, backend: Backend) -> Result<(), Failure> {
    use talus::run::estimate::{self, Rate};
    let total = run::total_steps(&sim);
    let work = run::expected_work(&sim, total);
    out!(
        "expected work: {:.3e} particle-steps (moving particles × steps, the insertions at their rates; to stop.time, the settling rule may end it sooner)",
        work.total()
    );
    let hardware_gpu = matches!(
        device::choose_adapter(),
        Ok(a) if a.get_info().device_type != wgpu::DeviceType::Cpu
    );
    let mut backends = vec![Backend::Cpu];
    match backend {
        Backend::Cpu => {}
        Backend::Gpu => backends = vec![Backend::Gpu],
        Backend::Auto if hardware_gpu => backends.push(Backend::Gpu),
        Backend::Auto => {
            out!("(no hardware GPU: the CPU path only; --backend gpu times a software adapter)")
        }
    }
    let final_count = (0..=10)
        .map(|k| run::expected_moving(&sim, sim.dt() * (total * k / 10) as f64))
        .fold(0.0, f64::max);
    let pour = final_count > 2.0 * sim.particles.mobile_count() as f64;
    let mut work = work;
    let mut start = None;
    if pour {
        // The pour's first seconds, for the pace of its sources: one that waits for its
        // spot at the outlet places fewer particles than its rate says, and the run
        // then does less work (and builds a smaller heap by its end).
        let (rate, _, _, _, now) = time_engine_keep(&sim, Backend::Cpu, 3.0, None, false)?;
        // Its rate then stands for the heap while it is small (a few falling grains
        // and the first of the heap: the per-step costs weigh most there), at the mean
        // of its moving particles then.
        if let Some(r) = rate {
            start = Some(Rate {
                particles: 0.5
                    * (sim.particles.mobile_count() + now.particles.mobile_count()) as f64,
                per_second: r,
            });
        }
        let pace = estimate::source_pace(&now);
        if pace.iter().any(|&p| p < 0.9) {
            for (k, p) in pace.iter().enumerate().filter(|(_, p)| **p < 0.9) {
                out!(
                    "point source {k} places {:.0} % of its rate in its first {:.3} time units: a spot at its outlet is free only once the grain before has fallen clear of it (a faster drop, a wider spread or a lower rate keeps up)",
                    100.0 * p,
                    now.time()
                );
            }
            let slowed = Simulation::new(estimate::at_pace(&sim.scene, &pace))?;
            work = run::expected_work(&slowed, total);
            out!(
                "expected work at that pace: {:.3e} particle-steps (and {:.0} particles by the end)",
                work.total(),
                (0..=10)
                    .map(|k| run::expected_moving(&slowed, sim.dt() * (total * k / 10) as f64))
                    .fold(0.0, f64::max)
            );
        }
    }
    let final_count = if pour {
        (0..=10)
            .map(|k| {
                let at = (total * k / 10).max(1);
                (work.at(at) - work.at(at - 1)).max(0.0)
            })
            .fold(0.0, f64::max)
            .max(1.0)
    } else {
        final_count
    };
    let piles: Vec<(usize, Simulation)> = if pour {
        let mut piles = Vec::new();
        for n in estimate::pile_sizes(final_count) {
            let Some(pile) = estimate::grown_pile(&sim.scene, n)? else {
                break;
            };
            piles.push((n, pile));
        }
        piles
    } else {
        Vec::new()
    };
    for b in backends {
        if piles.is_empty() {
            let (rate, from, to, (name, _)) = time_engine(&sim, b, 3.0, Some(&work))?;
            let Some(rate) = rate else {
                out!("{name}: no moving particles in the timed steps; no estimate");
                continue;
            };
            out!(
                "{name}: {rate:.3e} particle-steps/s over steps {from}–{to} → about {} for the whole run",
                duration(work.total() / rate),
            );
            continue;
        }
        let (mut rates, mut name) = (Vec::new(), String::new());
        // The pour's own start, timed on the CPU path above.
        if b == Backend::Cpu {
            if let Some(r) = start.filter(|r| r.particles >= 1.0) {
                out!(
                    "{}: the pour's start ({:.0} moving on average): {:.3e} particle-steps/s",
                    "cpu",
                    r.particles,
                    r.per_second
                );
                rates.push(r);
            }
        }
        for (n, pile) in &piles {
            let (rate, _, to, engine) = time_engine(pile, b, 2.0, None)?;
            let contacts;
            (name, contacts) = engine;
            if let Some(r) = rate {
                let moving = pile.particles.mobile_count() as f64;
                out!(
                    "{name}: the heap grown to {n} (a lattice pile of {} moving, {:.1} contacts each at the end): {r:.3e} particle-steps/s over {to} steps",
                    moving as usize,
                    2.0 * contacts as f64 / pile.particles.len() as f64
                );
                rates.push(Rate {
                    particles: moving,
                    per_second: r,
                });
            }
        }
        if rates.is_empty() {
            out!("{name}: the stand-in piles did not move; no estimate");
            continue;
        }
        let (lo, hi) = (rates.iter())
            .map(|r| r.per_second)
            .fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(r), b.max(r)));
        out!(
            "{name}: {lo:.3e}–{hi:.3e} particle-steps/s as the heap grows → about {} for the whole run (its expected work at the rate of the heap at its size, step range by step range)",
            duration(estimate::run_time(&work, &rates))
        );
    }
    Ok(())
}

/// `sim` on backend b for about `seconds` after a warm-up of 10 steps, in doubling
/// batches: its rate (particle-steps/s; None if nothing moved), the steps timed, and the
/// engine's name and its contacts at the end. With
/// `work`, the run's expected work over those steps, up to its stop time; without (a
/// stand-in pile or a pour's start), the mean of its moving particles at the start and
/// the end times the steps, whatever its stop time. `settle`: first until its particles
/// touch three others on average (a stand-in pile), for at most 4000 steps and 30 s.
fn time_engine_keep(
    sim: &Simulation,
    b: Backend,
    seconds: f64,
    work: Option<&talus::base::progress::Work>,
    settle: bool,
) -> Result<(Option<f64>, u64, u64, (String, usize), Simulation), Failure> {
    let total = run::total_steps(sim).max(1);
    let start = checkpoint::Checkpoint::fresh(sim.clone());
    let mut engine = match b {
        Backend::Gpu => Engine::Gpu(Box::new(GpuSimulation::resume(start.sim, start.device)?)),
        _ => Engine::cpu(start.sim),
    };
    let diverged = |e| Failure::failed(format!("the scene diverged while timed: {e}"));
    engine.advance(10.min(total)).map_err(diverged)?;
    if settle {
        // A stand-in pile first settles into contact (a lattice of irregular shapes
        // starts with gaps between many neighbours): until its particles touch three
        // others on average, for at most 4000 steps and 30 s.
        let t = std::time::Instant::now();
        let (mut batch, mut steps) = (64, 0);
        while steps < 4000 && t.elapsed().as_secs_f64() < 30.0 {
            engine.advance(batch).map_err(diverged)?;
            steps += batch;
            let now = (engine.sim())
                .map_err(|e| Failure::failed(format!("the device was lost while timed: {e}")))?;
            if 2 * now.pairs.len() >= 3 * now.particles.len() {
                break;
            }
            batch *= 2;
        }
    }
    let (from, t) = (engine.step(), std::time::Instant::now());
    let moving_from = (engine.sim())
        .map_err(|e| Failure::failed(format!("the device was lost while timed: {e}")))?
        .particles
        .mobile_count() as f64;
    let mut batch = 8;
    let limit = if work.is_some() { total } else { u64::MAX };
    while t.elapsed().as_secs_f64() < seconds && engine.step() < limit {
        let k = batch.min(limit - engine.step());
        engine.advance(k).map_err(diverged)?;
        batch *= 2;
    }
    // The GPU runs ahead of the host: a readback waits for it.
    let now = (engine.sim())
        .map_err(|e| Failure::failed(format!("the device was lost while timed: {e}")))?;
    let (moving, contacts) = (now.particles.mobile_count() as f64, now.pairs.len());
    let now = now.clone();
    let moving = 0.5 * (moving + moving_from);
    let seconds = t.elapsed().as_secs_f64();
    let to = engine.step();
    let done = match work {
        Some(w) => w.at(to) - w.at(from),
        None => moving * (to - from) as f64,
    };
    Ok((
        (done > 0.0).then(|| done / seconds),
        from,
        to,
        (engine.name(), contacts),
        now,
    ))
}

/// `time_engine_keep` without the state it reached.
fn time_engine(
    sim: &Simulation,
    b: Backend,
    seconds: f64,
    work: Option<&talus::base::progress::Work>,
) -> Result<(Option<f64>, u64, u64, (String, usize)), Failure> {
    let (rate, from, to, named, _) = time_engine_keep(sim, b, seconds, work, work.is_none())?;
    Ok((rate, from, to, named))
}

/// A duration in words: seconds, minutes, hours or days.
fn duration(seconds: f64) -> String {
    match seconds {
        s if s < 120.0 => format!("{s:.0} s"),
        s if s < 7200.0 => format!("{:.0} min", s / 60.0),
        s if s < 172_800.0 => format!("{:.1} h", s / 3600.0),
        s => format!("{:.1} days", s / 86_400.0),
    }
}

/// What the scene's point sources and layered rows will add during the run, and when:
/// a pour starts with no grains, and "0 particles at start" alone says nothing of it.
fn what_creators_add(sim: &Simulation) -> Vec<String> {
    let (sources, layered) = talus::sim::creators(&sim.scene);
    let copies = sim.scene.replicas.max(1) as u64;
    let each = if copies > 1 {
        format!(" in each of the {copies} copies")
    } else {
        String::new()
    };
    let unit = if sim.scene.units == scene::Units::Si {
        " s"
    } else {
        ""
    };
    let mut lines = Vec::new();
    let mut total = 0u64;
    for (k, s) in sources.iter().enumerate() {
        let shape = if s.polygon.is_some() {
            "polygons"
        } else if s.rod.is_some() {
            "rods"
        } else {
            "disks"
        };
        let end = s.start_time + s.count as f64 / s.rate;
        let per = if unit.is_empty() { "time unit" } else { "s" };
        lines.push(format!(
            "point source {k}: {} {shape}{each}, {} per {per} from t = {}{unit} to t = {}{unit} \
             (later while its spot at the outlet is taken), dropped from ({}, {}) ± {} in x",
            s.count,
            s.rate,
            s.start_time,
            (end * 1e4).round() / 1e4,
            s.position[0],
            s.position[1],
            s.spread
        ));
        total += s.count as u64 * copies;
    }
    for (k, l) in layered.iter().enumerate() {
        let rows = talus::scene::rows::max_rows(l);
        let most: u64 = (0..rows)
            .map(|r| talus::create::layered::row_capacity(l, r) as u64)
            .sum();
        lines.push(format!(
            "layered pile {k}: at most {rows} rows, {most} particles{each}, a row every {}{unit} from t = {}{unit} \
             (each row where the pile is still below its {}° outline)",
            l.interval, l.start_time, l.slope
        ));
        total += most * copies;
    }
    if !lines.is_empty() {
        lines.push(format!(
            "created during the run: up to {total} particles, {} in all",
            total + sim.particles.len() as u64
        ));
    }
    lines
}
