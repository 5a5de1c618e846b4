//! Impacts simulated per second on one core.
//!
//! Run: `cargo bench -p bouncelab-model --bench simulate`
//! An impact runs from 15 ms before touch to separation (2 m/s, 15° from the normal, paper's clay values);
//! "sampled" also returns the trajectory at 10,000 fps over a 40 ms clip, as a fit does.

use bouncelab_model::effects::{Hertz, HuntCrossley, TangentialSpring};
use bouncelab_model::{Ball, Model, SimOptions, State, simulate};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn start() -> State {
    let a = 15f64.to_radians();
    State::flying(0.0, Ball::TENNIS.radius_m + 0.03, 2.0 * a.sin(), -2.0 * a.cos())
}

fn bench(c: &mut Criterion) {
    let o = SimOptions::default();
    let times: Vec<f64> = (0..400).map(|i| i as f64 * 1e-4).collect();
    let mut g = c.benchmark_group("impact");
    g.throughput(Throughput::Elements(1));
    let base = Model::paper(25_650.0, 14.0, 0.5);
    g.bench_function("base", |b| {
        b.iter(|| simulate(black_box(&base), 0.0, 0.0, start(), &[], &o).unwrap())
    });
    g.bench_function("base_sampled_400", |b| {
        b.iter(|| simulate(black_box(&base), 0.0, 0.0, start(), &times, &o).unwrap())
    });
    let rich = base
        .clone()
        .with(Hertz { k_h: 1e5 })
        .with(HuntCrossley { lambda: 1e3, n: 1.0 });
    g.bench_function("base_hertz_hunt_crossley", |b| {
        b.iter(|| simulate(black_box(&rich), 0.0, 0.0, start(), &[], &o).unwrap())
    });
    let custom = bouncelab_model::ModelSpec::parse(
        "[effects.spring]\nk = 25650\n[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n[effects.pull]\nkind = \"custom\"\nnormal = \"-f0 * exp(-delta / d0)\"\nf0 = 1\nd0 = 5e-4\n",
        "bench",
    )
    .unwrap()
    .build(None)
    .unwrap();
    g.bench_function("base_custom_formula", |b| {
        b.iter(|| simulate(black_box(&custom), 0.0, 0.0, start(), &[], &o).unwrap())
    });
    let names: Vec<String> = (0..33).map(|i| format!("p{i}")).collect();
    let decl: String = names.iter().map(|n| format!("{n} = 0.01\n")).collect();
    let wide = bouncelab_model::ModelSpec::parse(
        &format!(
            "[effects.spring]\nk = 25650\n[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n[effects.wide]\nkind = \"custom\"\nnormal = \"({}) * delta\"\n{decl}",
            names.join(" + ")
        ),
        "bench",
    )
    .unwrap()
    .build(None)
    .unwrap();
    g.bench_function("base_custom_formula_33_names", |b| {
        b.iter(|| simulate(black_box(&wide), 0.0, 0.0, start(), &[], &o).unwrap())
    });
    let spring = base.clone().with(TangentialSpring {
        compliance: 1e-5,
        c_t: 0.0,
    });
    g.bench_function("base_tangential_spring", |b| {
        b.iter(|| simulate(black_box(&spring), 0.0, 0.0, start(), &[], &o).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
