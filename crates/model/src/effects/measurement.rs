//! Measurement effects: they change what the camera sees, not how the ball moves.

use super::{Effect, EffectInfo, Observation, ParamSpec, effect_params};

/// Camera roll: the image axes are turned by `φ` (counter-clockwise) with respect to the surface.
///
/// What the pipeline takes for the local frame is then the true frame rotated by `−φ`: gravity seems to
/// have a tangential part, a normal impact looks oblique, and the measured restitution and friction mix
/// normal and tangential motion.
#[derive(Debug, Clone)]
pub struct CameraRoll {
    /// Roll of the camera with respect to the surface, degrees, counter-clockwise.
    pub roll_deg: f64,
}

impl CameraRoll {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "camera_roll",
            doc: "Camera roll: the image axes are turned by φ with respect to the surface, so the observed frame is the true one rotated by −φ.",
            group: "measurement",
            base: false,
            params: &[ParamSpec {
                name: "roll_deg",
                unit: "deg",
                doc: "camera roll, counter-clockwise",
                default: Some(0.0),
                neutral: 0.0,
                min: -45.0,
                max: 45.0,
            }],
            build: |v| Box::new(CameraRoll { roll_deg: v[0] }),
        }
    }
}

impl Effect for CameraRoll {
    effect_params!("camera_roll", roll_deg);
    fn observe(&self, obs: &mut Observation) {
        let phi = self.roll_deg.to_radians();
        let (s, c) = phi.sin_cos();
        let rot = |x: f64, y: f64| (c * x + s * y, -s * x + c * y);
        (obs.x, obs.y) = rot(obs.x, obs.y);
        (obs.vx, obs.vy) = rot(obs.vx, obs.vy);
        obs.theta -= phi;
    }
}

/// Surface level: the surface line found in the image lies `level_m` above the plane the ball touches.
///
/// The line a tracker finds is the band's visible top edge: on a grainy or lit edge it sits a fraction of
/// a pixel off the contact plane, and a camera slightly above or below the surface sees a near or far edge.
/// The pipeline measures heights from that line, so every measured height is `level_m` too large. A
/// nuisance of the measurement rather than physics: `analyze` fits it per surface with the base model,
/// and the missing-effect search never proposes it.
#[derive(Debug, Clone)]
pub struct SurfaceLevel {
    /// Height of the found surface line above the contact plane, m.
    pub level_m: f64,
}

impl SurfaceLevel {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "surface_level",
            doc: "Surface level: the surface line found in the image lies level_m above the plane the ball touches, so measured heights are level_m too large (a nuisance, fitted per surface).",
            group: "nuisance",
            base: true,
            params: &[ParamSpec {
                name: "level_m",
                unit: "m",
                doc: "height of the found surface line above the contact plane",
                default: Some(0.0),
                neutral: 0.0,
                min: -0.005,
                max: 0.005,
            }],
            build: |v| Box::new(SurfaceLevel { level_m: v[0] }),
        }
    }
}

impl Effect for SurfaceLevel {
    effect_params!("surface_level", level_m);
    fn observe(&self, obs: &mut Observation) {
        obs.y += self.level_m;
    }
}
