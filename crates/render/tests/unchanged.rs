//! Guards the renderer's output bit for bit: the `smoke` preset renders as it did before looks existed (its
//! frames and truth underpin regression tests and the accuracy tables in docs/accuracy.md), and
//! `looks-smoke` as it did before the renderer was split into named steps.

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

/// The hash of a shot's frames 0, maximum compression and last: each one's size and its gray levels (16-bit
/// ones little-endian).
fn key_frames_hash(plan: &ShotPlan) -> u64 {
    let r = plan.renderer();
    let max = plan.frames.iter().position(|f| f.t_s >= plan.truth.t_max_s).unwrap();
    let mut h = FNV_START;
    for i in [0, max, plan.frames.len() - 1] {
        let f = r.frame(i);
        h = fnv(f.width.to_le_bytes().into_iter().chain(f.height.to_le_bytes()), h);
        h = match &f.pixels {
            Pixels::Gray8(px) => fnv(px.iter().copied(), h),
            Pixels::Gray16(px) => fnv(px.iter().flat_map(|v| v.to_le_bytes()), h),
        };
    }
    h
}

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
        assert_eq!(plan.camera().bit_depth, 8, "smoke is 8-bit");
        let truth = format!("{:?}{:?}", plan.truth, plan.frames);
        got.push((key_frames_hash(&plan), fnv(truth.bytes(), FNV_START)));
    }
    assert_eq!(got, SMOKE, "smoke's frames or truth changed: got {got:#x?}");
}

/// Hashes of each `looks-smoke` shot: the pixels of frames 0, maximum compression and the last frame, the
/// first frame as encoded in the shot's file format, and the shot's truth and drawn look, computed before
/// the renderer's long functions were split into named steps (issue 20). Looks exercise every painter
/// (surfaces, clutter, glare), 8-, 12- and 16-bit output, PNG and TIFF.
const LOOKS_SMOKE: [(u64, u64, u64); 6] = [
    (0xfb9c344ce9bd6159, 0x57e72e9ab1d9a4ea, 0x13c67f118e553dc2),
    (0x1b9e2bb698eb79ed, 0x21c9a9f98fe6fcbb, 0xb33cbada13017f78),
    (0x16983af40b15ce83, 0x2119fb225b40d2aa, 0x299097aa89431172),
    (0x099944aba910cb1f, 0xca2cf9283814cc75, 0x8475b5f82c3437a0),
    (0x6d7bef092ba1a7c8, 0x9b8f4f2e8f564058, 0xe76a9f54a9d5d8aa),
    (0x9a4bc56a2c506608, 0xcd3994b5c108ea3e, 0x5dbdbe7343a990ff),
];

#[test]
fn looks_smoke_preset_renders_as_pinned() {
    let s = Scenario::preset("looks-smoke").unwrap();
    let mut got = Vec::new();
    for shot in 0..s.shots.len() {
        let plan = ShotPlan::new(&s, shot).unwrap();
        let file = bouncelab_render::encode(&plan.renderer().frame(0), plan.camera().format).unwrap();
        let truth = format!("{:?}{:?}{:?}", plan.truth, plan.frames, plan.look);
        got.push((
            key_frames_hash(&plan),
            fnv(file, FNV_START),
            fnv(truth.bytes(), FNV_START),
        ));
    }
    assert_eq!(
        got, LOOKS_SMOKE,
        "looks-smoke's frames, files or truth changed: got {got:#x?}"
    );
}
