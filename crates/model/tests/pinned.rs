//! Pins the simulator's outputs bit for bit: trajectories and impacts of a few shots covering every phase,
//! both friction states and their switches, a compliant patch, extra effects and a flight filmed either
//! side. A change of arithmetic anywhere in the integration (step control, event location, re-stepping to
//! an event) moves these hashes; the accuracy tests beside them would not see a change in the last bits
//! that the renderer's pinned clips and the acceptance tables would.

use bouncelab_model::effects::TangentialSpring;
use bouncelab_model::{Ball, Model, ModelSpec, SimOptions, Simulation, State, simulate, simulate_drop};

/// FNV-1a, 64 bits: a fixed, documented hash (std's `DefaultHasher` may change between Rust releases).
fn fnv(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// `Debug` prints every f64 in its shortest round-trip form, so equal text means equal bits.
fn hash(sim: &Simulation) -> u64 {
    fnv(format!("{sim:?}").as_bytes())
}

fn grid(t0: f64, dt: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| t0 + i as f64 * dt).collect()
}

fn at_touch(speed: f64, angle_deg: f64, spin: f64) -> State {
    let a = angle_deg.to_radians();
    State {
        omega: spin,
        ..State::flying(0.0, Ball::TENNIS.radius_m + 1e-3, speed * a.sin(), -speed * a.cos())
    }
}

fn run(model: &Model, incline_deg: f64, start: State, times: &[f64]) -> Simulation {
    simulate(
        model,
        incline_deg.to_radians(),
        0.0,
        start,
        times,
        &SimOptions::default(),
    )
    .unwrap()
}

/// The paper's model with Hertzian stiffness and drag added, from a model file.
fn with_extras() -> Model {
    let text = format!(
        "{}\n[effects.hertz]\nk_h = 600000\n[effects.drag]\ncd = 1.5\nrho = 1.204\n",
        bouncelab_model::PAPER_MODEL_TOML
    );
    ModelSpec::parse(&text, "pinned test")
        .unwrap()
        .build(Some("clay"))
        .unwrap()
}

#[test]
fn simulations_are_bit_identical_to_the_pinned_ones() {
    let times = grid(0.0, 1e-4, 120);
    let got = [
        // Normal impact: compression, restitution, no friction switch.
        hash(&run(
            &Model::paper(25_650.0, 14.0, 0.5),
            0.0,
            at_touch(2.0, 0.0, 0.0),
            &times,
        )),
        // Oblique, large friction: sliding, then sticking to separation (rolling).
        hash(&run(
            &Model::paper(25_650.0, 14.0, 2.0),
            0.0,
            at_touch(3.0, 40.0, 0.0),
            &times,
        )),
        // Incline: sticks, then the grip is lost near separation.
        hash(&run(
            &Model::paper(25_650.0, 14.0, 0.8),
            22.5,
            at_touch(2.0, 22.5, 0.0),
            &times,
        )),
        // Back-spin against the slide: the slip reverses.
        hash(&run(
            &Model::paper(30_800.0, 15.0, 0.3),
            0.0,
            at_touch(2.5, 30.0, -150.0),
            &times,
        )),
        // A compliant patch (its own stick/slip events and history states).
        hash(&run(
            &Model::paper(25_650.0, 14.0, 0.5).with(TangentialSpring {
                compliance: 1e-5,
                c_t: 0.0,
            }),
            0.0,
            at_touch(2.5, 25.0, 0.0),
            &times,
        )),
        // Extra effects, dropped from a height onto an incline, filmed from the release over the impact.
        hash(
            &simulate_drop(
                &with_extras(),
                15f64.to_radians(),
                0.35,
                &grid(0.2, 1e-4, 900),
                &SimOptions::default(),
            )
            .unwrap(),
        ),
    ];
    assert_eq!(got, PINNED, "the simulator's outputs changed: got {got:#x?}");
}

/// The hashes above, computed before `integrate` was split into named steps.
const PINNED: [u64; 6] = [
    0x32a9a392a5309a57,
    0xeab70bf49dec530d,
    0xd2271488e68486c3,
    0x67fd8ddc48064a1b,
    0x78b4e0feb94063e5,
    0xf260e8daa3128982,
];
