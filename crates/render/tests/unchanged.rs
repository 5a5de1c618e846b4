//! Guards the scenarios without `[look]`: the `smoke` preset renders bit for bit as it did before looks
//! existed (its frames and truth underpin regression tests and the accuracy tables in docs/accuracy.md).

use bouncelab_render::{Pixels, Scenario, ShotPlan};

/// FNV-1a, 64 bits: a fixed, documented hash (std's `DefaultHasher` may change between Rust releases).
fn fnv(bytes: impl IntoIterator<Item = u8>, mut h: u64) -> u64 {
    for b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// Hashes of the pixels of frames 0, maximum compression and the last frame of each `smoke` shot, and of
/// each shot's truth (shot row and every frame row), computed before scenarios could have a `[look]`.
const SMOKE: [(u64, u64); 3] = [
    (0xa9305eef538ba90c, 0x925bee29fa06a2c0),
    (0x4bde4b91461fea34, 0xdd30595d94dc4c65),
    (0x435afb2a8c72b479, 0x9493134240604962),
];

#[test]
fn smoke_preset_renders_as_before_looks() {
    let s = Scenario::preset("smoke").unwrap();
    let mut got = Vec::new();
    for shot in 0..s.shots.len() {
        let plan = ShotPlan::new(&s, shot).unwrap();
        let r = plan.renderer();
        let max = plan.frames.iter().position(|f| f.t_s >= plan.truth.t_max_s).unwrap();
        let mut h = FNV_START;
        for i in [0, max, plan.frames.len() - 1] {
            let f = r.frame(i);
            let Pixels::Gray8(px) = &f.pixels else {
                panic!("smoke is 8-bit")
            };
            h = fnv(f.width.to_le_bytes().into_iter().chain(f.height.to_le_bytes()), h);
            h = fnv(px.iter().copied(), h);
        }
        let truth = format!("{:?}{:?}", plan.truth, plan.frames);
        got.push((h, fnv(truth.bytes(), FNV_START)));
    }
    assert_eq!(got, SMOKE, "smoke's frames or truth changed: got {got:#x?}");
}
