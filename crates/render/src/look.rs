//! Looks: a shot's appearance (surface band, lighting, clutter, ball, sensor, camera geometry) drawn from
//! the ranges of the scenario's `[look]` table, so the pipeline is tested on many looks rather than one.
//!
//! Drawing happens in two steps, both from the shot's look stream: [`LookSpec::draw`] picks every
//! parameter before the camera is placed (it decides the frame size and the scale), and [`Look::place`]
//! puts the clutter, hot spots and the tape strip once the ball's path in the image is known, so that the
//! truth lists only what is really in the frames.

use crate::RenderError;
use crate::rng::Rng;
use crate::scenario::{Camera, Downslope, Format, Texture};
use crate::shot::Geometry;
use serde::Deserialize;

/// A closed interval of values, written in a scenario as `[low, high]` or as one number (a fixed value).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Range {
    /// Lowest value.
    pub lo: f64,
    /// Highest value.
    pub hi: f64,
}

impl Range {
    /// The interval [lo, hi].
    pub const fn new(lo: f64, hi: f64) -> Range {
        Range { lo, hi }
    }

    /// A value drawn uniformly from the interval.
    pub(crate) fn draw(&self, rng: &mut Rng) -> f64 {
        let u = rng.uniform();
        if self.hi > self.lo {
            (self.lo + (self.hi - self.lo) * u).min(self.hi)
        } else {
            self.lo
        }
    }

    /// A whole number drawn uniformly from the integers of the interval.
    pub(crate) fn draw_count(&self, rng: &mut Rng) -> u32 {
        let (lo, hi) = (self.lo.ceil().max(0.0), self.hi.floor().max(0.0));
        let u = rng.uniform();
        if hi > lo {
            ((lo + (u * (hi - lo + 1.0)).floor()).min(hi)) as u32
        } else {
            lo as u32
        }
    }

    /// A value drawn uniformly and rounded to a whole number within the interval (which must hold one).
    pub(crate) fn draw_whole(&self, rng: &mut Rng) -> u32 {
        self.draw(rng).round().clamp(self.lo.ceil(), self.hi.floor()).max(0.0) as u32
    }

    /// True if `x` lies in the interval (with a relative tolerance of 1e-9 for values written to text).
    pub fn contains(&self, x: f64) -> bool {
        let tol = 1e-9 * (1.0 + self.lo.abs().max(self.hi.abs()));
        x >= self.lo - tol && x <= self.hi + tol
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}, {}]", self.lo, self.hi)
    }
}

impl<'de> Deserialize<'de> for Range {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Range, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            One(f64),
            Two([f64; 2]),
        }
        match Raw::deserialize(d).map_err(|_| serde::de::Error::custom("expected a number or [low, high]"))? {
            Raw::One(x) => Ok(Range::new(x, x)),
            Raw::Two([lo, hi]) => Ok(Range::new(lo, hi)),
        }
    }
}

/// What a shot's surface band looks like (the surface families of `docs/renderer.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceLook {
    /// Granular clay: a speckle of grains with a ragged top edge.
    ClaySpeckle,
    /// Plain-weave tape: threads crossing over and under.
    WovenTape,
    /// Herringbone (twill) tape: diagonal ribs turning every few periods.
    HerringboneTape,
    /// A strip of tape lying on a clay band; the ball lands on the tape.
    TapeOnClay,
}

impl SurfaceLook {
    /// Name as written in scenario and truth files.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceLook::ClaySpeckle => "clay_speckle",
            SurfaceLook::WovenTape => "woven_tape",
            SurfaceLook::HerringboneTape => "herringbone_tape",
            SurfaceLook::TapeOnClay => "tape_on_clay",
        }
    }
    /// True if the band has clay (with its ragged edge).
    pub fn has_clay(self) -> bool {
        matches!(self, SurfaceLook::ClaySpeckle | SurfaceLook::TapeOnClay)
    }
    /// True if the band has a tape.
    pub fn has_tape(self) -> bool {
        self != SurfaceLook::ClaySpeckle
    }
    /// The tape's weave, `plain` or `herringbone` (a tape on clay has either, as drawn), or none for clay.
    fn weave(self, herringbone_on_clay: bool) -> Option<&'static str> {
        match self {
            SurfaceLook::ClaySpeckle => None,
            SurfaceLook::WovenTape => Some("plain"),
            SurfaceLook::HerringboneTape => Some("herringbone"),
            SurfaceLook::TapeOnClay => Some(if herringbone_on_clay { "herringbone" } else { "plain" }),
        }
    }
}

/// How the moving ball looks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BallLook {
    /// A bright felt ball with its seam, lit from the front at a drawn direction.
    FeltSeam,
    /// The same felt without a seam.
    Plain,
    /// A dark silhouette in front of a bright backdrop (backlit, as shadowgraph clips are).
    Backlit,
}

impl BallLook {
    /// Name as written in scenario and truth files.
    pub fn name(self) -> &'static str {
        match self {
            BallLook::FeltSeam => "felt_seam",
            BallLook::Plain => "plain",
            BallLook::Backlit => "backlit",
        }
    }
}

/// A static object in the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ItemKind {
    /// A ruler with ticks and digit-like marks, on the backdrop (behind the ball's path).
    Ruler,
    /// A round fixture: a dark disc with a bright bevel, rings and a bore.
    Fixture,
    /// A screw head: a small bright dome with a slot, or a dark socket.
    Screw,
    /// A second ball, at rest on the surface beside the path.
    RestingBall,
    /// A ball-sized ring on the backdrop.
    Ring,
    /// A ball-sized lamp (a bright disc with a glow) on the backdrop.
    Lamp,
    /// A hand-like dark blob reaching in from a frame edge.
    Hand,
}

impl ItemKind {
    /// Name as written in truth files.
    pub fn name(self) -> &'static str {
        match self {
            ItemKind::Ruler => "ruler",
            ItemKind::Fixture => "fixture",
            ItemKind::Screw => "screw",
            ItemKind::RestingBall => "resting_ball",
            ItemKind::Ring => "ring",
            ItemKind::Lamp => "lamp",
            ItemKind::Hand => "hand",
        }
    }
}

/// A static object placed in a shot's frames; none touches the ball's path except a ruler, which hangs
/// behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Item {
    /// What it is.
    pub kind: ItemKind,
    /// Centre, pixels (x right; a ruler's middle, a hand's palm).
    pub x_px: f64,
    /// Centre, pixels (y down).
    pub y_px: f64,
    /// Radius, pixels (a ruler's half-length, a hand's reach).
    pub r_px: f64,
    /// Bright (true) or dark (false): a screw, a ring, a ruler's body.
    pub bright: bool,
    /// Orientation, rad counter-clockwise as seen: a screw's slot, a ruler's length, a hand's fingers.
    pub angle_rad: f64,
    /// A ruler's width, a ring's thickness, a hand's finger width, a fixture's bevel, pixels (else 0).
    pub width_px: f64,
    /// A ruler's tick spacing, the spacing of a fixture's rings, pixels (else 0).
    pub spacing_px: f64,
}

/// A static specular blob (glare) added to the background.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HotSpot {
    /// Centre, pixels.
    pub x_px: f64,
    /// Centre, pixels.
    pub y_px: f64,
    /// Gaussian standard deviation, pixels.
    pub sigma_px: f64,
    /// Peak brightness added, DN (8-bit scale).
    pub peak_dn: f64,
}

/// The `[look]` table: the ranges each shot's appearance is drawn from. Every key is optional; the
/// defaults cover the ranges of `docs/renderer.md` ("Looks"). A list of choices is drawn uniformly (repeat an
/// entry to weight it); a range is `[low, high]` or one number.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LookSpec {
    /// Looks of surfaces whose texture is `clay`.
    pub clay_looks: Vec<SurfaceLook>,
    /// Looks of surfaces whose texture is a tape (`white_tape`, `green_tape`).
    pub tape_looks: Vec<SurfaceLook>,
    /// Backdrop level just above the surface line, before lighting, DN (8-bit scale).
    pub backdrop_dn: Range,
    /// Backdrop level for backlit balls, DN.
    pub backlit_backdrop_dn: Range,
    /// Band mean at its top minus the backdrop level above it, DN (≈ 0: the edge shows only as texture).
    pub band_offset_dn: Range,
    /// Standard deviation of the band's texture (speckle or weave) in its top 16 px, DN.
    pub texture_dn: Range,
    /// Brightness added along the band's top edge (its lip catching the light; < 0 a shadow), DN.
    pub lip_dn: Range,
    /// RMS height of the clay's ragged top edge about its mean line, pixels.
    pub edge_roughness_px: Range,
    /// Correlation length of the clay's edge (its grain scale), pixels.
    pub edge_scale_px: Range,
    /// Size of the clay's grains, pixels.
    pub grain_px: Range,
    /// RMS height of a tape's top edge, pixels.
    pub tape_edge_roughness_px: Range,
    /// Period of a tape's weave, pixels (3 fine … 12 coarse).
    pub weave_period_px: Range,
    /// How far a tape lying on clay stands above the clay's mean edge, pixels.
    pub tape_thickness_px: Range,
    /// Lighting gradient: relative change of the illumination from the frame's centre to its edge.
    pub gradient: Range,
    /// Number of hot spots (static specular blobs).
    pub hot_spots: Range,
    /// Vignetting: relative brightness lost in the corners.
    pub vignetting: Range,
    /// Probability of a ruler.
    pub ruler: f64,
    /// Number of round fixtures with rings.
    pub fixtures: Range,
    /// Number of screw heads.
    pub screws: Range,
    /// Radius of a screw head, pixels.
    pub screw_radius_px: Range,
    /// Probability of a second static ball-sized circle (a resting ball, a ring or a lamp).
    pub second_circle: f64,
    /// Probability of a hand-like dark blob at a frame edge.
    pub hand: f64,
    /// Looks of the moving ball.
    pub balls: Vec<BallLook>,
    /// Brightest albedo of a felt ball, DN.
    pub ball_albedo_dn: Range,
    /// Level of a backlit ball's silhouette, DN.
    pub backlit_ball_dn: Range,
    /// Elevation of the light on a felt ball above the image plane, degrees (its azimuth is uniform).
    pub light_elevation_deg: Range,
    /// Read noise, standard deviation, DN (8-bit scale).
    pub read_noise_dn: Range,
    /// Bits of the frame files: 8, 12 (12-bit data in 16-bit files, values × 16) or 16.
    pub bit_depths: Vec<u8>,
    /// File formats.
    pub formats: Vec<Format>,
    /// File name patterns without extension (`{}` or `{:0N}`: the frame number); the extension follows the
    /// format (`.png`, `.tif`).
    pub naming: Vec<String>,
    /// Down-slope directions in the image.
    pub downslopes: Vec<Downslope>,
    /// Camera roll, degrees (adds to `camera.roll_deg`).
    pub roll_deg: Range,
    /// Ball radius in the image, pixels (sets the scale).
    pub ball_radius_px: Range,
    /// Frame width, pixels.
    pub width_px: Range,
    /// Frame height, pixels.
    pub height_px: Range,
}

impl Default for LookSpec {
    fn default() -> Self {
        LookSpec {
            clay_looks: vec![SurfaceLook::ClaySpeckle],
            tape_looks: vec![
                SurfaceLook::WovenTape,
                SurfaceLook::HerringboneTape,
                SurfaceLook::TapeOnClay,
            ],
            backdrop_dn: Range::new(40.0, 200.0),
            backlit_backdrop_dn: Range::new(140.0, 225.0),
            band_offset_dn: Range::new(-40.0, 40.0),
            texture_dn: Range::new(4.0, 25.0),
            lip_dn: Range::new(-10.0, 20.0),
            edge_roughness_px: Range::new(0.0, 6.0),
            edge_scale_px: Range::new(1.0, 12.0),
            grain_px: Range::new(1.5, 6.0),
            tape_edge_roughness_px: Range::new(0.0, 1.0),
            weave_period_px: Range::new(3.0, 12.0),
            tape_thickness_px: Range::new(0.0, 3.0),
            gradient: Range::new(0.0, 0.5),
            hot_spots: Range::new(0.0, 3.0),
            vignetting: Range::new(0.0, 0.6),
            ruler: 0.3,
            fixtures: Range::new(0.0, 2.0),
            screws: Range::new(0.0, 3.0),
            screw_radius_px: Range::new(4.0, 12.0),
            second_circle: 0.35,
            hand: 0.2,
            balls: vec![BallLook::FeltSeam, BallLook::Plain, BallLook::Backlit],
            ball_albedo_dn: Range::new(150.0, 240.0),
            backlit_ball_dn: Range::new(10.0, 60.0),
            light_elevation_deg: Range::new(15.0, 80.0),
            read_noise_dn: Range::new(1.0, 12.0),
            bit_depths: vec![8, 12, 16],
            formats: vec![Format::Png, Format::Tiff],
            naming: vec![
                "C001H001S0001{:06}".into(),
                "img_{}".into(),
                "frame{:05}".into(),
                "shot_{:04}".into(),
            ],
            downslopes: vec![Downslope::PlusX, Downslope::MinusX],
            roll_deg: Range::new(-2.0, 2.0),
            ball_radius_px: Range::new(20.0, 100.0),
            width_px: Range::new(320.0, 640.0),
            height_px: Range::new(320.0, 640.0),
        }
    }
}

/// Lowest and highest gray level a band or backdrop is given, DN: room for texture and noise.
const LEVEL_MIN: f64 = 15.0;
const LEVEL_MAX: f64 = 235.0;

/// The family tags a look can carry (the `families` column of `truth/looks.csv`), with what each means.
pub const LOOK_FAMILIES: &[(&str, &str)] = &[
    ("clay_speckle", "granular clay band with a ragged top edge"),
    ("woven_tape", "plain-weave tape band"),
    ("herringbone_tape", "herringbone (twill) tape band"),
    (
        "tape_on_clay",
        "a tape strip lying on a clay band, the ball landing on the tape",
    ),
    ("low_contrast", "band mean within 10 DN of the backdrop above it"),
    ("band_brighter", "band mean at least 10 DN above the backdrop"),
    (
        "band_darker",
        "band mean at least 10 DN below the backdrop (inverted polarity)",
    ),
    (
        "gradient",
        "illumination changes by 15 % or more from the centre to an edge",
    ),
    ("hot_spots", "one or more static specular blobs"),
    ("strong_vignetting", "35 % or more of the light lost in the corners"),
    ("even_light", "none of gradient, hot_spots, strong_vignetting"),
    ("ruler", "a ruler with ticks and digit-like marks"),
    ("fixtures", "round fixtures with rings"),
    ("screws", "screw heads (radius 4-12 px)"),
    (
        "second_circle",
        "a second static ball-sized circle (resting ball, ring or lamp)",
    ),
    ("hand", "a hand-like dark blob at a frame edge"),
    ("no_clutter", "none of the clutter above"),
    ("felt_seam", "bright felt ball with its seam"),
    ("plain_ball", "felt ball without a seam"),
    ("backlit_ball", "dark ball silhouette on a bright backdrop"),
    ("noise_low", "read noise below 4 DN"),
    ("noise_mid", "read noise 4 to 8 DN"),
    ("noise_high", "read noise 8 DN or more"),
    ("8bit", "8-bit files"),
    ("12in16", "12-bit data in 16-bit files (values x 16)"),
    ("16bit", "16-bit files"),
    ("minus_x", "down-slope is -x in the image (mirrored)"),
    ("rolled", "camera roll of 1 degree or more"),
    ("small_ball", "ball radius below 40 px"),
    ("large_ball", "ball radius 70 px or more"),
];

/// A shot's drawn appearance: the look parameters (truth, in `truth/looks.csv`) and the placed clutter.
/// Levels are in DN of the 8-bit scale before lighting (illumination, vignetting) and noise.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// The surface family.
    pub surface: SurfaceLook,
    /// Backdrop level just above the surface line, DN.
    pub backdrop_dn: f64,
    /// Band mean at its top (the tape's where the ball lands), DN.
    pub band_dn: f64,
    /// For a tape on clay: the clay's mean at its top, DN.
    pub clay_dn: Option<f64>,
    /// Standard deviation of the band's texture in its top 16 px, DN.
    pub texture_dn: f64,
    /// Brightness added along the top edge, DN.
    pub lip_dn: f64,
    /// Clay: RMS height of its top edge about its mean line, pixels.
    pub edge_roughness_px: Option<f64>,
    /// Clay: correlation length of its edge, pixels.
    pub edge_scale_px: Option<f64>,
    /// Clay: grain size, pixels.
    pub grain_px: Option<f64>,
    /// Tape: RMS height of its top edge, pixels.
    pub tape_edge_roughness_px: Option<f64>,
    /// Tape: weave period, pixels.
    pub weave_period_px: Option<f64>,
    /// Tape: its weave, `"plain"` (woven) or `"herringbone"`.
    pub weave: Option<&'static str>,
    /// Tape on clay: height of the tape above the clay's mean edge, pixels.
    pub tape_thickness_px: Option<f64>,
    /// Tape on clay: image x of the strip's two ends on the surface line, pixels (left, right).
    pub tape_span_px: Option<(f64, f64)>,
    /// Relative illumination change from the frame's centre to its edge along `gradient_dir_deg`.
    pub gradient: f64,
    /// Direction of increasing light, degrees counter-clockwise from +x as seen.
    pub gradient_dir_deg: f64,
    /// Vignetting: relative brightness lost in the corners.
    pub vignetting: f64,
    /// Hot spots (static glare).
    pub hot_spots: Vec<HotSpot>,
    /// Static objects placed in the frame.
    pub items: Vec<Item>,
    /// The ball's look.
    pub ball: BallLook,
    /// Felt: brightest albedo; backlit: the silhouette's level, DN.
    pub ball_dn: f64,
    /// Light on a felt ball: azimuth, degrees counter-clockwise from +x as seen.
    pub light_azimuth_deg: f64,
    /// Light on a felt ball: elevation above the image plane, degrees.
    pub light_elevation_deg: f64,
    /// Read noise, DN.
    pub read_noise_dn: f64,
    /// Bits of the files: 8, 12 (in 16-bit files, × 16) or 16.
    pub bit_depth: u8,
    /// File format.
    pub format: Format,
    /// File name pattern (with its extension).
    pub naming: String,
    /// Down-slope direction in the image.
    pub downslope: Downslope,
    /// The look's camera roll, degrees (the shot's total is in `ShotTruth::roll_deg`).
    pub roll_deg: f64,
    /// Ball radius in the image, pixels.
    pub ball_radius_px: f64,
    /// Frame width, pixels.
    pub width_px: u32,
    /// Frame height, pixels.
    pub height_px: u32,
    /// Drawn before placement, kept for the painter (not truth).
    pub(crate) draft: Draft,
}

/// Parameters the painter needs that are not part of the truth.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Draft {
    /// Seed of the look's images (textures, edges).
    pub seed: u64,
    /// Vertical foreshortening of the band's texture (the camera looks along the surface).
    pub foreshortening: f64,
    /// Darkening of the band with depth, DN.
    pub fade_dn: f64,
    /// Width of the lip, pixels.
    pub lip_px: f64,
    /// Backdrop: change of level from the surface line to the top of the frame, DN.
    pub backdrop_ramp_dn: f64,
    /// Backdrop: smooth blotches, DN.
    pub blotch_dn: f64,
    /// Backdrop: fine texture (paper, cloth), DN.
    pub backdrop_grain_dn: f64,
    /// Surface line height as a fraction of the frame height, before it is moved down to fit the path.
    pub line_frac: f64,
    /// Felt: ambient share of the shading; backlit: 1.
    pub ambient: f64,
    /// Brightening toward the ball's silhouette.
    pub rim: f64,
    /// Tape: correlation length of its edge, pixels.
    pub tape_edge_scale_px: f64,
    /// Herringbone: ribs turn every this many periods.
    pub zig_periods: f64,
    /// Tape on clay: the strip reaches this fraction of the band's depth.
    pub tape_depth_frac: f64,
    /// Tape on clay: strip ends beyond the contact, in ball radii (left, right).
    pub tape_margins: (f64, f64),
    /// Hot spots to place.
    pub hot_spots: u32,
    /// A ruler to place.
    pub ruler: bool,
    /// Fixtures to place.
    pub fixtures: u32,
    /// Screws to place.
    pub screws: u32,
    /// The range screw radii are drawn from at placement, pixels.
    pub screw_radius: Range,
    /// A second ball-sized circle to place.
    pub second_circle: bool,
    /// A hand to place.
    pub hand: bool,
    /// Tape on clay: the strip's ends along the surface, pixels from the line's origin.
    pub tape_s: (f64, f64),
}

impl Draft {
    /// Draws the painter's parameters (one draw each, in this order, whatever the look); the clutter to
    /// place is left empty. `backlit`: the ball is a silhouette (ambient 1, a stronger rim).
    fn draw(rng: &mut Rng, backlit: bool) -> Draft {
        Draft {
            seed: rng.next_u64(),
            foreshortening: rng.range(1.2, 2.5),
            fade_dn: rng.range(0.0, 25.0),
            lip_px: rng.range(1.0, 3.0),
            backdrop_ramp_dn: rng.range(-25.0, 25.0),
            blotch_dn: rng.range(1.0, 6.0),
            backdrop_grain_dn: rng.range(0.0, 2.5),
            line_frac: rng.range(0.62, 0.85),
            ambient: if backlit {
                rng.uniform();
                1.0
            } else {
                rng.range(0.25, 0.45)
            },
            rim: if backlit {
                rng.range(0.2, 1.0)
            } else {
                rng.range(0.1, 0.35)
            },
            tape_edge_scale_px: rng.range(2.0, 8.0),
            zig_periods: rng.range(2.5, 4.0),
            tape_depth_frac: rng.range(0.3, 1.0),
            tape_margins: (rng.range(0.4, 3.0), rng.range(0.4, 3.0)),
            ..Draft::default()
        }
    }
}

fn pick<T: Copy>(rng: &mut Rng, v: &[T]) -> T {
    v[((rng.uniform() * v.len() as f64) as usize).min(v.len() - 1)]
}

/// A band offset drawn from `range` but kept where backdrop + offset stays within the gray levels given
/// to textured surfaces.
fn draw_offset(rng: &mut Rng, range: Range, backdrop: f64) -> f64 {
    let lo = range.lo.max(LEVEL_MIN - backdrop);
    let hi = range.hi.min(LEVEL_MAX - backdrop);
    if lo <= hi {
        Range::new(lo, hi).draw(rng)
    } else {
        rng.uniform();
        // The range lies wholly outside the allowed levels: the nearest allowed offset.
        if range.lo > LEVEL_MAX - backdrop {
            LEVEL_MAX - backdrop
        } else {
            LEVEL_MIN - backdrop
        }
    }
}

impl LookSpec {
    /// Checks every range and list; `origin` names the scenario in errors.
    pub(crate) fn check(&self, origin: &str) -> Result<(), RenderError> {
        let bad = |field: &str, value: String, reason: &str| RenderError::InvalidValue {
            origin: origin.to_string(),
            field: format!("look.{field}"),
            value,
            reason: reason.to_string(),
        };
        let ranges: [(&str, Range, f64, f64, &str); 25] = [
            ("backdrop_dn", self.backdrop_dn, LEVEL_MIN, LEVEL_MAX, "DN"),
            (
                "backlit_backdrop_dn",
                self.backlit_backdrop_dn,
                LEVEL_MIN,
                LEVEL_MAX,
                "DN",
            ),
            ("band_offset_dn", self.band_offset_dn, -200.0, 200.0, "DN"),
            ("texture_dn", self.texture_dn, 0.0, 60.0, "DN"),
            ("lip_dn", self.lip_dn, -60.0, 60.0, "DN"),
            ("edge_roughness_px", self.edge_roughness_px, 0.0, 20.0, "px"),
            ("edge_scale_px", self.edge_scale_px, 0.5, 100.0, "px"),
            ("grain_px", self.grain_px, 0.5, 40.0, "px"),
            ("tape_edge_roughness_px", self.tape_edge_roughness_px, 0.0, 10.0, "px"),
            ("weave_period_px", self.weave_period_px, 2.0, 60.0, "px"),
            ("tape_thickness_px", self.tape_thickness_px, 0.0, 20.0, "px"),
            ("gradient", self.gradient, 0.0, 0.9, "(relative)"),
            ("hot_spots", self.hot_spots, 0.0, 20.0, "(a count)"),
            ("vignetting", self.vignetting, 0.0, 0.9, "(relative)"),
            ("fixtures", self.fixtures, 0.0, 10.0, "(a count)"),
            ("screws", self.screws, 0.0, 20.0, "(a count)"),
            ("screw_radius_px", self.screw_radius_px, 1.0, 60.0, "px"),
            ("ball_albedo_dn", self.ball_albedo_dn, 20.0, 255.0, "DN"),
            ("backlit_ball_dn", self.backlit_ball_dn, 0.0, 200.0, "DN"),
            ("light_elevation_deg", self.light_elevation_deg, 0.0, 90.0, "degrees"),
            ("read_noise_dn", self.read_noise_dn, 0.0, 40.0, "DN"),
            ("roll_deg", self.roll_deg, -45.0, 45.0, "degrees"),
            ("ball_radius_px", self.ball_radius_px, 4.0, 2000.0, "px"),
            ("width_px", self.width_px, 64.0, 8192.0, "px"),
            ("height_px", self.height_px, 64.0, 8192.0, "px"),
        ];
        for (name, r, min, max, unit) in ranges {
            if !(r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi) {
                return Err(bad(name, r.to_string(), "must be finite with low ≤ high"));
            }
            if r.lo < min || r.hi > max {
                return Err(bad(
                    name,
                    r.to_string(),
                    &format!("must lie within {min} to {max} {unit}"),
                ));
            }
        }
        for (name, r) in [("width_px", self.width_px), ("height_px", self.height_px)] {
            if r.lo.ceil() > r.hi.floor() {
                return Err(bad(name, r.to_string(), "must hold a whole number of pixels"));
            }
        }
        for (name, p) in [
            ("ruler", self.ruler),
            ("second_circle", self.second_circle),
            ("hand", self.hand),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(bad(name, p.to_string(), "a probability: must be 0 to 1"));
            }
        }
        let empty = |name: &str| bad(name, "[]".into(), "must list at least one choice");
        if self.clay_looks.is_empty() {
            return Err(empty("clay_looks"));
        }
        if self.tape_looks.is_empty() {
            return Err(empty("tape_looks"));
        }
        if self.balls.is_empty() {
            return Err(empty("balls"));
        }
        if self.bit_depths.is_empty() {
            return Err(empty("bit_depths"));
        }
        if let Some(b) = self.bit_depths.iter().find(|b| ![8, 12, 16].contains(*b)) {
            return Err(bad("bit_depths", b.to_string(), "must be 8, 12 or 16"));
        }
        if self.formats.is_empty() {
            return Err(empty("formats"));
        }
        if self.downslopes.is_empty() {
            return Err(empty("downslopes"));
        }
        if self.naming.is_empty() {
            return Err(empty("naming"));
        }
        for n in &self.naming {
            for ext in [".png", ".tif"] {
                crate::scenario::parse_naming(&format!("{n}{ext}"))
                    .map_err(|reason| bad("naming", format!("{n:?}"), &reason))?;
            }
        }
        Ok(())
    }

    /// The ball's look and the backdrop level that goes with it (both levels drawn, the ball's kept).
    fn draw_ball_and_backdrop(&self, rng: &mut Rng) -> (BallLook, f64) {
        let ball = pick(rng, &self.balls);
        let normal_backdrop = self.backdrop_dn.draw(rng);
        let backlit_backdrop = self.backlit_backdrop_dn.draw(rng);
        let backdrop_dn = if ball == BallLook::Backlit {
            backlit_backdrop
        } else {
            normal_backdrop
        };
        (ball, backdrop_dn)
    }

    /// The looks a surface of texture `texture` may take.
    fn surface_looks(&self, texture: Texture) -> &[SurfaceLook] {
        if texture == Texture::Clay {
            &self.clay_looks
        } else {
            &self.tape_looks
        }
    }

    /// Draws a shot's look (everything but the placement of clutter, which [`Look::place`] does once the
    /// path is known) for a surface of texture `texture`.
    pub(crate) fn draw(&self, rng: &mut Rng, texture: Texture) -> Look {
        // Every value is drawn whether or not the chosen families use it, so a change of one list does not
        // shift the others' draws.
        let (ball, backdrop_dn) = self.draw_ball_and_backdrop(rng);
        let surface = pick(rng, self.surface_looks(texture));
        let band_offset = draw_offset(rng, self.band_offset_dn, backdrop_dn);
        let clay_offset = draw_offset(rng, self.band_offset_dn, backdrop_dn);
        let texture_dn = self.texture_dn.draw(rng);
        let lip_dn = self.lip_dn.draw(rng);
        let edge_roughness = self.edge_roughness_px.draw(rng);
        let edge_scale = self.edge_scale_px.draw(rng);
        let grain = self.grain_px.draw(rng);
        let tape_edge = self.tape_edge_roughness_px.draw(rng);
        let weave = self.weave_period_px.draw(rng);
        let herringbone_on_clay = rng.uniform() < 0.5;
        let thickness = self.tape_thickness_px.draw(rng);
        let gradient = self.gradient.draw(rng);
        let gradient_dir_deg = rng.range(0.0, 360.0);
        let hot_spots = self.hot_spots.draw_count(rng);
        let vignetting = self.vignetting.draw(rng);
        let ruler = rng.uniform() < self.ruler;
        let fixtures = self.fixtures.draw_count(rng);
        let screws = self.screws.draw_count(rng);
        let second_circle = rng.uniform() < self.second_circle;
        let hand = rng.uniform() < self.hand;
        let albedo = self.ball_albedo_dn.draw(rng);
        let backlit_level = self.backlit_ball_dn.draw(rng);
        let light_azimuth_deg = rng.range(0.0, 360.0);
        let light_elevation_deg = self.light_elevation_deg.draw(rng);
        let read_noise_dn = self.read_noise_dn.draw(rng);
        let bit_depth = pick(rng, &self.bit_depths);
        let format = pick(rng, &self.formats);
        let stem = &self.naming[((rng.uniform() * self.naming.len() as f64) as usize).min(self.naming.len() - 1)];
        let downslope = pick(rng, &self.downslopes);
        let roll_deg = self.roll_deg.draw(rng);
        let ball_radius_px = self.ball_radius_px.draw(rng);
        let width_px = self.width_px.draw_whole(rng);
        let height_px = self.height_px.draw_whole(rng);
        let draft = Draft {
            hot_spots,
            ruler,
            fixtures,
            screws,
            screw_radius: self.screw_radius_px,
            second_circle,
            hand,
            ..Draft::draw(rng, ball == BallLook::Backlit)
        };
        let clay = surface.has_clay();
        let tape = surface.has_tape();
        Look {
            surface,
            backdrop_dn,
            band_dn: backdrop_dn + band_offset,
            clay_dn: (surface == SurfaceLook::TapeOnClay).then_some(backdrop_dn + clay_offset),
            texture_dn,
            lip_dn,
            edge_roughness_px: clay.then_some(edge_roughness),
            edge_scale_px: clay.then_some(edge_scale),
            grain_px: clay.then_some(grain),
            tape_edge_roughness_px: tape.then_some(tape_edge),
            weave_period_px: tape.then_some(weave),
            weave: surface.weave(herringbone_on_clay),
            tape_thickness_px: (surface == SurfaceLook::TapeOnClay).then_some(thickness),
            tape_span_px: None,
            gradient,
            gradient_dir_deg,
            vignetting,
            hot_spots: Vec::new(),
            items: Vec::new(),
            ball,
            ball_dn: if ball == BallLook::Backlit {
                backlit_level
            } else {
                albedo
            },
            light_azimuth_deg,
            light_elevation_deg,
            read_noise_dn,
            bit_depth,
            format,
            naming: format!("{stem}{}", format.extension()),
            downslope,
            roll_deg,
            ball_radius_px,
            width_px,
            height_px,
            draft,
        }
    }
}

/// The extent of a shot's path in the rolled local frame, metres: what the frame must hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PathExtent {
    /// Horizontal extent of the centres (all sub-exposure positions), m.
    pub width_m: f64,
    /// Highest point of the ball above the surface line, m.
    pub top_m: f64,
}

/// What [`Look::place`] needs to know about a placed shot.
pub(crate) struct Placement<'a> {
    pub geom: Geometry,
    pub width: f64,
    pub height: f64,
    pub r_px: f64,
    /// Ball centres at every sub-exposure time, pixels.
    pub path: &'a [(f64, f64)],
    /// Ball centres during contact, pixels.
    pub contact: &'a [(f64, f64)],
}

impl Placement<'_> {
    /// y of the surface line (the contact plane) at image column x.
    fn line_y(&self, x: f64) -> f64 {
        let g = self.geom;
        g.ty + g.sin * (x - g.tx) / (g.dir * g.cos)
    }

    /// True if a disc of radius `r` at (x, y) keeps clear of the ball at every sub-exposure position.
    fn clear_of_path(&self, x: f64, y: f64, r: f64) -> bool {
        let d = self.r_px + r + 4.0;
        self.path
            .iter()
            .all(|&(px, py)| (px - x) * (px - x) + (py - y) * (py - y) > d * d)
    }

    fn inside(&self, x: f64, y: f64, r: f64) -> bool {
        x - r >= 2.0 && x + r <= self.width - 3.0 && y - r >= 2.0 && y + r <= self.height - 3.0
    }
}

impl Look {
    /// Sets the camera keys the look draws: frame size, scale (from the ball radius `r_m`, m), roll (added),
    /// down-slope, read noise, vignetting, bits, format and naming.
    pub(crate) fn apply_to(&self, cam: &mut Camera, r_m: f64) {
        cam.width = self.width_px;
        cam.height = self.height_px;
        cam.scale_m_per_px = r_m / self.ball_radius_px;
        cam.roll_deg += self.roll_deg;
        cam.downslope = self.downslope;
        cam.read_noise = self.read_noise_dn;
        cam.vignetting = self.vignetting;
        cam.bit_depth = self.bit_depth;
        cam.format = self.format;
        cam.naming = Some(self.naming.clone());
    }

    /// Makes the path fit the frame: the frame grows (within the spec's size ranges) and then, if that is not
    /// enough, the ball shrinks (within its radius range). Returns true if the path fits.
    pub(crate) fn fit_frame(&mut self, spec: &LookSpec, ext: PathExtent, r_m: f64) -> bool {
        // Room the placement needs: 8 px either side, 6 px above the ball's top, the line at most at 94 %.
        let need = |r_px: f64| {
            let per_m = r_px / r_m;
            (
                (ext.width_m + 2.0 * r_m) * per_m + 16.0,
                (ext.top_m * per_m + 6.0) / 0.94,
            )
        };
        let grow = |look: &mut Look, r_px: f64| {
            let (nw, nh) = need(r_px);
            look.width_px = look
                .width_px
                .max((nw.ceil() as u32).min(spec.width_px.hi.floor() as u32));
            look.height_px = look
                .height_px
                .max((nh.ceil() as u32).min(spec.height_px.hi.floor() as u32));
        };
        grow(self, self.ball_radius_px);
        let fits = |look: &Look| {
            let (nw, nh) = need(look.ball_radius_px);
            nw <= look.width_px as f64 && nh <= look.height_px as f64
        };
        if fits(self) {
            return true;
        }
        let (w, h) = (self.width_px as f64, self.height_px as f64);
        let r_w = (w - 16.0) * r_m / (ext.width_m + 2.0 * r_m);
        let r_h = (0.94 * h - 6.0) * r_m / ext.top_m.max(1e-9);
        self.ball_radius_px = r_w.min(r_h).min(self.ball_radius_px).max(spec.ball_radius_px.lo);
        fits(self)
    }

    /// Places the hot spots, the tape strip (tape on clay) and the clutter once the camera is placed; what
    /// finds no room is left out, so `items` lists what the frames show.
    pub(crate) fn place(&mut self, rng: &mut Rng, p: &Placement) {
        let d = self.draft.clone();
        for _ in 0..d.hot_spots {
            self.hot_spots.push(HotSpot {
                x_px: rng.range(0.0, p.width),
                y_px: rng.range(0.0, p.height),
                sigma_px: rng.range(3.0, 25.0),
                peak_dn: rng.range(30.0, 120.0),
            });
        }
        if self.surface == SurfaceLook::TapeOnClay {
            self.place_tape(p, d.tape_margins);
        }
        let mut items: Vec<Item> = Vec::new();
        if d.ruler {
            items.push(p.ruler(rng));
        }
        for _ in 0..d.fixtures {
            items.extend(p.fixture(rng, &items));
        }
        for _ in 0..d.screws {
            items.extend(p.screw(rng, &items, d.screw_radius));
        }
        if d.second_circle {
            items.extend(p.second_circle(rng, &items));
        }
        if d.hand {
            items.extend(p.hand(rng, &items));
        }
        self.items = items;
    }

    /// The tape strip on the clay: from `margins` ball radii (left, right) beyond the contact.
    fn place_tape(&mut self, p: &Placement, margins: (f64, f64)) {
        let r = p.r_px;
        let s: Vec<f64> = p.contact.iter().map(|&(x, y)| p.geom.to_local_px(x, y).0).collect();
        let (smin, smax) = s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        let (s0, s1) = (smin - margins.0 * r, smax + margins.1 * r);
        self.draft.tape_s = (s0, s1);
        let (x0, _) = p.geom.local_px_to_image(s0, 0.0);
        let (x1, _) = p.geom.local_px_to_image(s1, 0.0);
        self.tape_span_px = Some((x0.min(x1), x0.max(x1)));
    }
}

/// True if a disc of radius `rr` at (x, y) keeps 3 px clear of every placed item but rulers (which hang
/// behind).
fn free(items: &[Item], x: f64, y: f64, rr: f64) -> bool {
    items
        .iter()
        .filter(|i| i.kind != ItemKind::Ruler)
        .all(|i| (i.x_px - x).hypot(i.y_px - y) > i.r_px + rr + 3.0)
}

impl Placement<'_> {
    /// A ruler: horizontal above the surface (60 %) or standing on it near a side edge.
    fn ruler(&self, rng: &mut Rng) -> Item {
        let (w, h) = (self.width, self.height);
        let width = (0.4 * self.r_px).clamp(8.0, 40.0);
        let horizontal = rng.uniform() < 0.6;
        let tilt = rng.range(-2.0, 2.0).to_radians();
        let bright = rng.uniform() < 0.7;
        let tick = rng.range(3.0, 10.0);
        let (x, y, half, angle) = if horizontal {
            let top = 0.06 * h + width;
            let bottom = (self.line_y(w / 2.0) - width - 10.0).max(top);
            (
                rng.range(0.3 * w, 0.7 * w),
                rng.range(top, bottom),
                rng.range(0.4 * w, 0.7 * w),
                tilt,
            )
        } else {
            // Standing on the surface near a side edge.
            let x = if rng.uniform() < 0.5 {
                rng.range(0.03, 0.12) * w
            } else {
                rng.range(0.88, 0.97) * w
            };
            let bottom = self.line_y(x) + 2.0;
            let top = rng.range(-0.1, 0.3) * h;
            (
                x,
                0.5 * (top + bottom),
                0.5 * (bottom - top),
                std::f64::consts::FRAC_PI_2 + tilt,
            )
        };
        Item {
            kind: ItemKind::Ruler,
            x_px: x,
            y_px: y,
            r_px: half.max(width),
            bright,
            angle_rad: angle,
            width_px: width,
            spacing_px: tick,
        }
    }

    /// A round fixture above the surface or centred just outside an edge or corner (30 tries).
    fn fixture(&self, rng: &mut Rng, items: &[Item]) -> Option<Item> {
        let (w, r) = (self.width, self.r_px);
        let rf = (rng.range(0.4, 1.3) * r).max(8.0);
        let bevel = rng.range(0.05, 0.12) * rf;
        let ring_gap = rng.range(0.08, 0.2) * rf;
        for _ in 0..30 {
            let (x, y) = if rng.uniform() < 0.5 {
                (
                    rng.range(rf + 2.0, (w - rf - 3.0).max(rf + 2.0)),
                    rng.range(rf + 2.0, (self.line_y(w / 2.0) - rf).max(rf + 2.0)),
                )
            } else {
                // Centred just outside an edge or a corner, partly in view.
                let out = rng.range(0.2, 0.6) * rf;
                match (rng.uniform() * 4.0) as u32 {
                    0 => (-out, rng.range(0.0, self.line_y(0.0))),
                    1 => (w - 1.0 + out, rng.range(0.0, self.line_y(w - 1.0))),
                    2 => (rng.range(0.0, w), -out),
                    _ => (if rng.uniform() < 0.5 { -out } else { w - 1.0 + out }, -out),
                }
            };
            if self.clear_of_path(x, y, rf) && free(items, x, y, rf) {
                return Some(Item {
                    kind: ItemKind::Fixture,
                    x_px: x,
                    y_px: y,
                    r_px: rf,
                    bright: false,
                    angle_rad: 0.0,
                    width_px: bevel,
                    spacing_px: ring_gap,
                });
            }
        }
        None
    }

    /// A screw head of a radius drawn from `radius`: on the line (half the tries), above it or in the band
    /// (30 tries).
    fn screw(&self, rng: &mut Rng, items: &[Item], radius: Range) -> Option<Item> {
        let (w, h) = (self.width, self.height);
        let rs = radius.draw(rng);
        let bright = rng.uniform() < 0.6;
        let slot = rng.range(0.0, std::f64::consts::PI);
        for _ in 0..30 {
            let x = rng.range(rs + 2.0, (w - rs - 3.0).max(rs + 2.0));
            let ly = self.line_y(x);
            let mode = rng.uniform();
            let y = if mode < 0.5 {
                ly - 0.35 * rs
            } else if mode < 0.8 {
                rng.range(rs + 2.0, (ly - rs - 2.0).max(rs + 2.0))
            } else {
                rng.range(ly + rs + 3.0, (h - rs - 3.0).max(ly + rs + 3.0))
            };
            if self.inside(x, y, rs) && self.clear_of_path(x, y, rs) && free(items, x, y, rs) {
                return Some(Item {
                    kind: ItemKind::Screw,
                    x_px: x,
                    y_px: y,
                    r_px: rs,
                    bright,
                    angle_rad: slot,
                    width_px: 0.0,
                    spacing_px: 0.0,
                });
            }
        }
        None
    }

    /// A second ball-sized circle: a resting ball on the line, a ring or a lamp above it, the kinds tried in
    /// turn from a random one (40 tries each).
    fn second_circle(&self, rng: &mut Rng, items: &[Item]) -> Option<Item> {
        let (w, r) = (self.width, self.r_px);
        let first = (rng.uniform() * 3.0) as u32;
        for k in 0..3 {
            let kind = [ItemKind::RestingBall, ItemKind::Ring, ItemKind::Lamp][((first + k) % 3) as usize];
            let rr = r * rng.range(0.85, 1.15);
            let thick = rng.range(3.0, 8.0).min(0.4 * rr);
            let bright = rng.uniform() < 0.6;
            for _ in 0..40 {
                let x = rng.range(rr + 2.0, (w - rr - 3.0).max(rr + 2.0));
                let ly = self.line_y(x);
                let y = if kind == ItemKind::RestingBall {
                    ly - rr
                } else {
                    rng.range(rr + 2.0, (ly - rr - 3.0).max(rr + 2.0))
                };
                if self.inside(x, y, rr) && self.clear_of_path(x, y, rr) && free(items, x, y, rr) {
                    return Some(Item {
                        kind,
                        x_px: x,
                        y_px: y,
                        r_px: rr,
                        bright,
                        angle_rad: rng.range(0.0, std::f64::consts::TAU),
                        width_px: thick,
                        spacing_px: 0.0,
                    });
                }
            }
        }
        None
    }

    /// A hand reaching in from the left, right or top edge (12 tries).
    fn hand(&self, rng: &mut Rng, items: &[Item]) -> Option<Item> {
        let (w, h) = (self.width, self.height);
        let size = (1.2 * self.r_px).clamp(30.0, 0.35 * w.min(h));
        for _ in 0..12 {
            let side = (rng.uniform() * 3.0) as u32;
            let (x, y, angle) = match side {
                0 => (-0.25 * size, rng.range(0.15 * h, 0.85 * h), 0.0),
                1 => (
                    w - 1.0 + 0.25 * size,
                    rng.range(0.15 * h, 0.85 * h),
                    std::f64::consts::PI,
                ),
                _ => (
                    rng.range(0.15 * w, 0.85 * w),
                    -0.25 * size,
                    -std::f64::consts::FRAC_PI_2,
                ),
            };
            let angle = angle + rng.range(-0.4, 0.4);
            if self.clear_of_path(x, y, 1.3 * size) && free(items, x, y, 1.3 * size) {
                return Some(Item {
                    kind: ItemKind::Hand,
                    x_px: x,
                    y_px: y,
                    r_px: 1.3 * size,
                    bright: false,
                    angle_rad: angle,
                    width_px: rng.range(0.14, 0.2) * size,
                    spacing_px: 0.0,
                });
            }
        }
        None
    }
}

/// Columns of `truth/looks.csv` (one row per shot of a scenario with a `[look]`).
pub const LOOK_COLUMNS: &[&str] = &[
    "clip",
    "families",
    "surface_look",
    "ball_look",
    "backdrop_dn",
    "band_dn",
    "band_offset_dn",
    "clay_dn",
    "texture_dn",
    "lip_dn",
    "edge_roughness_px",
    "edge_scale_px",
    "grain_px",
    "tape_edge_roughness_px",
    "weave_period_px",
    "weave",
    "tape_thickness_px",
    "tape_x0_px",
    "tape_x1_px",
    "gradient",
    "gradient_dir_deg",
    "vignetting",
    "hot_spots",
    "ruler",
    "fixtures",
    "screws",
    "second_circle",
    "hand",
    "ball_dn",
    "light_azimuth_deg",
    "light_elevation_deg",
    "read_noise_dn",
    "bit_depth",
    "format",
    "naming",
    "downslope",
    "look_roll_deg",
    "ball_radius_px",
    "width_px",
    "height_px",
    "items",
];

impl Look {
    /// Number of placed items of `kind`.
    pub fn count(&self, kind: ItemKind) -> usize {
        self.items.iter().filter(|i| i.kind == kind).count()
    }

    /// The family tags of this look (see [`LOOK_FAMILIES`]), in the order of that list.
    pub fn families(&self) -> Vec<&'static str> {
        let mut f = vec![self.surface.name()];
        let offset = self.band_dn - self.backdrop_dn;
        f.push(if offset.abs() < 10.0 {
            "low_contrast"
        } else if offset > 0.0 {
            "band_brighter"
        } else {
            "band_darker"
        });
        let light_len = f.len();
        if self.gradient >= 0.15 {
            f.push("gradient");
        }
        if !self.hot_spots.is_empty() {
            f.push("hot_spots");
        }
        if self.vignetting >= 0.35 {
            f.push("strong_vignetting");
        }
        if f.len() == light_len {
            f.push("even_light");
        }
        let clutter_len = f.len();
        for (kind, tag) in [
            (ItemKind::Ruler, "ruler"),
            (ItemKind::Fixture, "fixtures"),
            (ItemKind::Screw, "screws"),
        ] {
            if self.count(kind) > 0 {
                f.push(tag);
            }
        }
        if self.second_circle().is_some() {
            f.push("second_circle");
        }
        if self.count(ItemKind::Hand) > 0 {
            f.push("hand");
        }
        if f.len() == clutter_len {
            f.push("no_clutter");
        }
        f.push(match self.ball {
            BallLook::FeltSeam => "felt_seam",
            BallLook::Plain => "plain_ball",
            BallLook::Backlit => "backlit_ball",
        });
        f.push(if self.read_noise_dn < 4.0 {
            "noise_low"
        } else if self.read_noise_dn < 8.0 {
            "noise_mid"
        } else {
            "noise_high"
        });
        f.push(match self.bit_depth {
            8 => "8bit",
            12 => "12in16",
            _ => "16bit",
        });
        if self.downslope == Downslope::MinusX {
            f.push("minus_x");
        }
        if self.roll_deg.abs() >= 1.0 {
            f.push("rolled");
        }
        if self.ball_radius_px < 40.0 {
            f.push("small_ball");
        } else if self.ball_radius_px >= 70.0 {
            f.push("large_ball");
        }
        f
    }

    /// The second ball-sized circle, if one was placed.
    pub fn second_circle(&self) -> Option<&Item> {
        self.items
            .iter()
            .find(|i| matches!(i.kind, ItemKind::RestingBall | ItemKind::Ring | ItemKind::Lamp))
    }

    /// The row of `truth/looks.csv` for clip `clip` (columns [`LOOK_COLUMNS`]).
    pub fn row(&self, clip: &str) -> Vec<String> {
        let num = |x: f64| (x + 0.0).to_string();
        let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
        let mut items: Vec<serde_json::Value> = self
            .items
            .iter()
            .map(|i| serde_json::json!({"kind": i.kind.name(), "x_px": i.x_px, "y_px": i.y_px, "r_px": i.r_px}))
            .collect();
        items.extend(
            self.hot_spots
                .iter()
                .map(|h| serde_json::json!({"kind": "hot_spot", "x_px": h.x_px, "y_px": h.y_px, "r_px": h.sigma_px})),
        );
        vec![
            clip.to_string(),
            self.families().join("+"),
            self.surface.name().to_string(),
            self.ball.name().to_string(),
            num(self.backdrop_dn),
            num(self.band_dn),
            num(self.band_dn - self.backdrop_dn),
            opt(self.clay_dn),
            num(self.texture_dn),
            num(self.lip_dn),
            opt(self.edge_roughness_px),
            opt(self.edge_scale_px),
            opt(self.grain_px),
            opt(self.tape_edge_roughness_px),
            opt(self.weave_period_px),
            self.weave.unwrap_or_default().to_string(),
            opt(self.tape_thickness_px),
            opt(self.tape_span_px.map(|s| s.0)),
            opt(self.tape_span_px.map(|s| s.1)),
            num(self.gradient),
            num(self.gradient_dir_deg),
            num(self.vignetting),
            self.hot_spots.len().to_string(),
            (self.count(ItemKind::Ruler) > 0).to_string(),
            self.count(ItemKind::Fixture).to_string(),
            self.count(ItemKind::Screw).to_string(),
            self.second_circle().map_or("none", |i| i.kind.name()).to_string(),
            (self.count(ItemKind::Hand) > 0).to_string(),
            num(self.ball_dn),
            num(self.light_azimuth_deg),
            num(self.light_elevation_deg),
            num(self.read_noise_dn),
            self.bit_depth.to_string(),
            match self.format {
                Format::Png => "png".into(),
                Format::Tiff => "tiff".into(),
            },
            self.naming.clone(),
            self.downslope.as_str().to_string(),
            num(self.roll_deg),
            num(self.ball_radius_px),
            self.width_px.to_string(),
            self.height_px.to_string(),
            serde_json::Value::Array(items).to_string(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::{any, prop_assert, proptest};

    proptest! {
        /// Whatever valid ranges a `[look]` gives, every drawn value lies in its range, and the band stays
        /// within the gray levels given to textured surfaces.
        #[test]
        fn drawn_values_lie_in_their_ranges(
            seed in any::<u64>(), a in 0.0f64..1.0, b in 0.0f64..1.0, clay in any::<bool>()
        ) {
            let r = |lo: f64, hi: f64| Range::new(lo + (hi - lo) * a.min(b), lo + (hi - lo) * a.max(b));
            let spec = LookSpec {
                backdrop_dn: r(LEVEL_MIN, LEVEL_MAX),
                band_offset_dn: r(-80.0, 80.0),
                texture_dn: r(0.0, 40.0),
                lip_dn: r(-30.0, 30.0),
                edge_roughness_px: r(0.0, 10.0),
                grain_px: r(0.5, 10.0),
                read_noise_dn: r(0.0, 30.0),
                roll_deg: r(-10.0, 10.0),
                ball_radius_px: r(5.0, 200.0),
                width_px: Range::new(64.0 + 900.0 * a.min(b), 65.0 + 900.0 * a.max(b)),
                height_px: Range::new(64.0 + 900.0 * a.min(b), 65.0 + 900.0 * a.max(b)),
                screws: r(0.0, 6.0),
                ..LookSpec::default()
            };
            spec.check("test").unwrap();
            let l = spec.draw(&mut Rng::new(seed), if clay { Texture::Clay } else { Texture::WhiteTape });
            let backdrop = if l.ball == BallLook::Backlit { spec.backlit_backdrop_dn } else { spec.backdrop_dn };
            prop_assert!(backdrop.contains(l.backdrop_dn));
            prop_assert!((LEVEL_MIN - 1e-9..=LEVEL_MAX + 1e-9).contains(&l.band_dn));
            let feasible = Range::new(
                spec.band_offset_dn.lo.max(LEVEL_MIN - l.backdrop_dn),
                spec.band_offset_dn.hi.min(LEVEL_MAX - l.backdrop_dn),
            );
            if feasible.lo <= feasible.hi {
                prop_assert!(spec.band_offset_dn.contains(l.band_dn - l.backdrop_dn));
            }
            prop_assert!(spec.texture_dn.contains(l.texture_dn) && spec.lip_dn.contains(l.lip_dn));
            prop_assert!(l.edge_roughness_px.is_none_or(|x| spec.edge_roughness_px.contains(x)));
            prop_assert!(l.grain_px.is_none_or(|x| spec.grain_px.contains(x)));
            prop_assert!(spec.read_noise_dn.contains(l.read_noise_dn) && spec.roll_deg.contains(l.roll_deg));
            prop_assert!(spec.ball_radius_px.contains(l.ball_radius_px));
            prop_assert!(spec.width_px.contains(l.width_px as f64) && spec.height_px.contains(l.height_px as f64));
            prop_assert!((l.draft.screws as f64) >= spec.screws.lo.ceil() && (l.draft.screws as f64) <= spec.screws.hi.floor().max(spec.screws.lo.ceil()));
            prop_assert!(l.grain_px.is_some() == (clay || l.surface == SurfaceLook::TapeOnClay));
        }
    }

    #[test]
    fn counts_are_whole_numbers_of_the_range() {
        let mut rng = Rng::new(1);
        let seen: std::collections::BTreeSet<u32> =
            (0..400).map(|_| Range::new(0.5, 3.0).draw_count(&mut rng)).collect();
        assert_eq!(seen.into_iter().collect::<Vec<_>>(), vec![1, 2, 3]);
        assert_eq!(Range::new(2.0, 2.0).draw_count(&mut rng), 2);
    }
}
