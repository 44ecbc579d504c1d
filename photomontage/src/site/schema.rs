//! The serde types of the site file, schema version 1. Field-by-field documentation lives in
//! `docs/site-format.md`; keep the two in step.

use serde::{Deserialize, Serialize};

mod lighting_fit;
mod materials;
mod names;
mod perez;
mod variants;

pub use lighting_fit::{
    FitRecord, FitSettings, HorizonSample, Sample, SamplePurpose, SunShadowPair,
};
pub use materials::{PaletteColour, SiteMaterial};
pub use names::{ModelUnits, ModelUpAxis, SkyModelName};
pub use perez::{PerezForm, PerezInputError, PerezInputs};
pub use variants::{Variant, VariantPlacement};

fn default_true() -> bool {
    true
}

fn default_sigma_px() -> f64 {
    0.5
}

fn default_sigma_m() -> [f64; 3] {
    [0.01, 0.01, 0.01]
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// The whole site file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Site {
    /// Always [`super::SCHEMA_VERSION`].
    pub schema_version: u32,
    /// A human name for the site.
    #[serde(default)]
    pub name: String,
    /// Where the site is on Earth (for the sun) and which coordinate system the survey uses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub location: Option<Location>,
    /// Settings of the camera solution.
    #[serde(default)]
    pub solve: SolveSettings,
    /// Lighting and atmosphere parameters.
    #[serde(default)]
    pub lighting: Lighting,
    /// Render settings.
    #[serde(default)]
    pub render: RenderSettings,
    /// The site photographs.
    #[serde(default)]
    pub photos: Vec<Photo>,
    /// Surveyed control points.
    #[serde(default)]
    pub control_points: Vec<ControlPoint>,
    /// Points computed from the photos (intersection / bundle adjustment), written by `solve`.
    #[serde(default)]
    pub tie_points: Vec<TiePoint>,
    /// Pixel observations of points in photos.
    #[serde(default)]
    pub observations: Vec<Observation>,
    /// Scene polygons of the existing (natural) environment.
    #[serde(default)]
    pub polygons: Vec<Polygon>,
    /// CAD models of the planned (artificial) objects.
    #[serde(default)]
    pub models: Vec<CadModel>,
    /// Artificial lights: luminaires with a photometric file (IES LM-63 or EULUMDAT).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub luminaires: Vec<SiteLuminaire>,
    /// Colour samples for the lighting fits (Durisch 1992 §4.2–4.3).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples: Vec<Sample>,
    /// Rectangles of sky at the horizon giving the horizon colour L∞.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub horizon_samples: Vec<HorizonSample>,
    /// Object/shadow point pairs for the sun cross-check.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sun_shadow_pairs: Vec<SunShadowPair>,
    /// Record of the last lighting fit, written by `fit`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitRecord>,
    /// Settings of the lighting fit (`[fit_settings]`).
    #[serde(default, skip_serializing_if = "FitSettings::is_default")]
    pub fit_settings: FitSettings,
    /// Site materials (`[[materials]]`): override the library's and the CAD files' material of
    /// the same name; a designer's colour may set the diffuse reflectance.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<SiteMaterial>,
    /// The site's named colours (`[[palette]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub palette: Vec<PaletteColour>,
    /// Design variants (`[[variants]]`): visible models, placements and materials per variant.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub variants: Vec<Variant>,
}

impl Default for Site {
    fn default() -> Self {
        Self {
            schema_version: super::SCHEMA_VERSION,
            name: String::new(),
            location: None,
            solve: SolveSettings::default(),
            lighting: Lighting::default(),
            render: RenderSettings::default(),
            photos: Vec::new(),
            control_points: Vec::new(),
            tie_points: Vec::new(),
            observations: Vec::new(),
            polygons: Vec::new(),
            models: Vec::new(),
            luminaires: Vec::new(),
            samples: Vec::new(),
            horizon_samples: Vec::new(),
            sun_shadow_pairs: Vec::new(),
            fit: None,
            fit_settings: FitSettings::default(),
            materials: Vec::new(),
            palette: Vec::new(),
            variants: Vec::new(),
        }
    }
}

/// The site's geographic location and survey coordinate system.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Location {
    /// Geodetic latitude of the site, degrees north (WGS 84).
    pub latitude_deg: f64,
    /// Geodetic longitude of the site, degrees east (WGS 84).
    pub longitude_deg: f64,
    /// Height above sea level in metres.
    #[serde(default)]
    pub elevation_m: f64,
    /// Name of the projected coordinate system of the control points (e.g. `EPSG:32611`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crs: Option<String>,
    /// Angle from grid north (the survey +Y axis) to true north, degrees clockwise (meridian
    /// convergence); 0 when the survey Y axis points to true north.
    #[serde(default)]
    pub grid_convergence_deg: f64,
    /// IANA time zone of the site (e.g. `Europe/Zurich`): local times without a UTC offset (EXIF
    /// capture times, sun-study times) are read in it, daylight saving time included.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_zone: Option<String>,
}

/// How cameras are solved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolveSettings {
    /// Run a bundle adjustment over all photos after the single-photo resections.
    pub bundle_adjustment: bool,
    /// Normalised residual (|v|/σ) above which an observation is flagged as an outlier.
    pub outlier_threshold_sigma: f64,
    /// Seed of the robust (RANSAC) start, so a solve is repeatable.
    pub seed: u64,
}

impl Default for SolveSettings {
    fn default() -> Self {
        Self {
            bundle_adjustment: true,
            outlier_threshold_sigma: 3.5,
            seed: 0,
        }
    }
}

/// One site photograph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Photo {
    /// Unique id, referred to by observations and polygons.
    pub id: String,
    /// Image file, relative to the site file (JPEG, PNG, TIFF or EXR).
    pub file: String,
    /// When the photo was taken (RFC 3339 with offset); overrides the EXIF time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taken_at: Option<String>,
    /// Interior orientation; when absent it is started from the camera profile, else from the
    /// EXIF focal length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interior: Option<Interior>,
    /// A camera profile written by `photomontage calibrate` (TOML, relative to the site file):
    /// the interior orientation `solve` starts from when `interior` is absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<String>,
    /// Which interior parameters the solver may estimate.
    #[serde(default)]
    pub self_calibration: SelfCalibrationFlags,
    /// Exterior orientation, written by `solve`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exterior: Option<Exterior>,
}

/// Interior orientation of one photo (see `camera` for the pixel convention).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Interior {
    /// Focal length in pixels.
    pub focal_px: f64,
    /// Principal point in pixels; the image centre when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub principal_point_px: Option<[f64; 2]>,
    /// Brown–Conrady coefficients.
    #[serde(default)]
    pub distortion: crate::camera::BrownConrady,
    /// Image size as displayed; read from the file when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_size_px: Option<[u32; 2]>,
}

/// Interior parameters the solver may estimate (only where the control geometry supports them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SelfCalibrationFlags {
    pub focal: bool,
    pub principal_point: bool,
    pub k1: bool,
    pub k2: bool,
}

/// A solved exterior orientation with its quality figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Exterior {
    /// Projection centre, world coordinates (metres).
    pub camera_center: [f64; 3],
    /// Rotation matrix taking camera-frame vectors to world-frame vectors, rows.
    pub rotation_world_from_camera: [[f64; 3]; 3],
    /// Root-mean-square reprojection residual of the enabled, non-outlier observations.
    #[serde(default)]
    pub rms_px: f64,
    /// Standard deviation of the camera centre per world axis (metres).
    #[serde(default)]
    pub sigma_center_m: [f64; 3],
    /// Which solver produced it: `resection` or `bundle`.
    #[serde(default)]
    pub solved_by: String,
}

/// A surveyed control point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlPoint {
    /// Unique point id (shared with tie points' id space).
    pub id: String,
    /// World coordinates X (east), Y (north), Z (up), metres.
    pub xyz: [f64; 3],
    /// Standard deviation per axis, metres; 0 holds the coordinate fixed.
    #[serde(default = "default_sigma_m")]
    pub sigma_m: [f64; 3],
    /// Name of the coordinate system if it differs from the site's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crs: Option<String>,
    /// Disabled control points are kept but not used.
    #[serde(default = "default_true")]
    pub enabled: bool,
}

/// A point whose coordinates were computed from the photos.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TiePoint {
    pub id: String,
    /// Estimated world coordinates (metres).
    pub xyz: [f64; 3],
    /// Their standard deviations (metres).
    #[serde(default)]
    pub sigma_m: [f64; 3],
}

/// The pixel position of a point in a photo.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Observation {
    /// Photo id.
    pub photo: String,
    /// Point id (a control point, or a tie point when no control point has it).
    pub point: String,
    /// Pixel x (right), pixel-centre convention.
    pub x_px: f64,
    /// Pixel y (down), pixel-centre convention.
    pub y_px: f64,
    /// Standard deviation of the measurement in pixels.
    #[serde(default = "default_sigma_px")]
    pub sigma_px: f64,
    /// Disabled observations are kept but not used.
    #[serde(default = "default_true")]
    pub enabled: bool,
}

/// A planar polygon of the existing environment (Durisch 1992 §4.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polygon {
    pub id: String,
    /// Ids of the vertex points (control or tie points), in order around the polygon.
    pub vertices: Vec<String>,
    /// Material attribute: a name in the material library.
    pub material: String,
    /// Image attribute: the photo its diffuse reflectance is read from by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<String>,
}

/// Lighting and atmosphere of the natural environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Lighting {
    /// Time for the sun position (RFC 3339); the current photo's time when absent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<String>,
    /// Sun direction given by hand (overrides the computed position).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun_manual: Option<SunManual>,
    /// Sky model: `uniform`, `cie_overcast`, `cie_general:N` with N in 1–15, or `perez`.
    pub sky_model: SkyModelName,
    /// Inputs of the Perez sky (read when `sky_model = "perez"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub perez: Option<PerezInputs>,
    /// Weight of direct sunlight k_s (Durisch eq. 6).
    pub sun_weight: [f64; 3],
    /// Weight of ambient light k_u.
    pub ambient_weight: [f64; 3],
    /// Weight of sky light k_h.
    pub sky_weight: [f64; 3],
    /// Atmosphere (Durisch eq. 2).
    pub atmosphere: Atmosphere,
    /// Material library file, relative to the site file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material_library: Option<String>,
    /// Whether the scene models the ground (radiosity): `false` lights the lower hemisphere from
    /// a uniform ground of `ground_albedo`; absent means modelled when a natural polygon faces
    /// up (within 30° of the zenith).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_modelled: Option<bool>,
    /// Albedo of the ground below the horizon where it is not modelled (default 0.2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_albedo: Option<[f64; 3]>,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            time: None,
            sun_manual: None,
            sky_model: SkyModelName::CieGeneral(12),
            perez: None,
            sun_weight: [1.0; 3],
            ambient_weight: [0.0; 3],
            sky_weight: [1.0; 3],
            atmosphere: Atmosphere::default(),
            material_library: None,
            ground_modelled: None,
            ground_albedo: None,
        }
    }
}

/// A hand-set sun direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunManual {
    /// Azimuth east of north, degrees.
    pub azimuth_deg: f64,
    /// Elevation above the horizon, degrees.
    pub elevation_deg: f64,
}

/// Atmosphere parameters per RGB channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Atmosphere {
    /// Extinction coefficient per metre (τ_a); 0 means clear air.
    pub extinction_per_m: [f64; 3],
    /// Horizon colour L∞ (linear RGB).
    pub horizon_colour: [f64; 3],
}

impl Default for Atmosphere {
    fn default() -> Self {
        Self {
            extinction_per_m: [0.0; 3],
            horizon_colour: [1.0; 3],
        }
    }
}

/// A CAD model of a planned object with its placement in the world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CadModel {
    pub id: String,
    /// OBJ, glTF/GLB or DXF file, relative to the site file.
    pub file: String,
    /// Length unit of the file: `m`, `cm`, `mm`, `in` or `ft`.
    #[serde(default)]
    pub units: ModelUnits,
    /// Up axis of the file: `z` or `y`.
    #[serde(default)]
    pub up_axis: ModelUpAxis,
    /// Placement in the world.
    #[serde(default)]
    pub placement: Placement,
    /// Hidden models are kept but not rendered.
    #[serde(default = "default_true", skip_serializing_if = "is_true")]
    pub visible: bool,
}

fn is_true(b: &bool) -> bool {
    *b
}

/// Where a model goes: scale, then rotation about the vertical axis, then translation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Placement {
    /// World position of the model's origin (metres).
    pub translation: [f64; 3],
    /// Rotation about world Z, degrees counter-clockwise seen from above.
    pub rotation_z_deg: f64,
    /// Uniform scale applied after the unit conversion.
    pub scale: f64,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            translation: [0.0; 3],
            rotation_z_deg: 0.0,
            scale: 1.0,
        }
    }
}

/// A luminaire of the site (an artificial light, Durisch 1992 §3.2 / §6.2 cases C and D1).
///
/// Photometric frame: with both angles 0 the luminaire hangs in its photometric position, nadir
/// (γ = 0) straight down (world −Z) and the C0 half-plane towards world +X (C90 towards +Y).
/// `tilt_deg` then swings the nadir up towards the C0 direction, and `rotation_z_deg` turns the
/// whole luminaire about the vertical: `world_from_luminaire = R_z(rotation_z) · R_y(−tilt)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteLuminaire {
    /// Unique id, named in errors and warnings.
    pub id: String,
    /// IES LM-63 (`.ies`) or EULUMDAT (`.ldt`) file, relative to the site file.
    pub file: String,
    /// Photometric centre, world coordinates (metres).
    pub position_m: [f64; 3],
    /// Rotation about world Z, degrees counter-clockwise seen from above (C0 from +X).
    #[serde(default)]
    pub rotation_z_deg: f64,
    /// Tilt of the nadir from straight down towards the C0 direction, degrees.
    #[serde(default)]
    pub tilt_deg: f64,
    /// Colour multiplier per RGB channel (linear).
    #[serde(default = "default_colour")]
    pub colour_rgb: [f64; 3],
    /// Photo linear units × m² per candela: a luminaire of I cd gives the irradiance
    /// `I · scale · colour / d²` in the units of `lighting.sun_weight`.
    pub scale: f64,
    /// Disabled luminaires are kept but give no light.
    #[serde(default = "default_true")]
    pub enabled: bool,
}

fn default_colour() -> [f64; 3] {
    [1.0; 3]
}

/// Render settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Fewest rays per pixel of the adaptive antialiasing.
    pub spp_min: u32,
    /// Most rays per pixel.
    pub spp_max: u32,
    /// Seed of the stochastic sampling.
    pub seed: u64,
    /// Trace spectral samples instead of RGB.
    #[serde(skip_serializing_if = "is_false")]
    pub spectral: bool,
    /// Reflection/refraction recursion limit.
    pub max_depth: u32,
    /// Radiosity lighting mode: sky and interreflected light from radiosity solutions of the
    /// site with and without the planned objects (docs/methodology.md).
    #[serde(default, skip_serializing_if = "is_false")]
    pub radiosity: bool,
    /// In the radiosity mode, the natural surfaces the rendered photo sees take their diffuse
    /// reflectance from it (`site::photo_reflectance`); `false` keeps the material library's
    /// (a photo with much the model lacks in front of its surfaces, or lighting studies under
    /// another sky than the photo's).
    #[serde(default = "default_true", skip_serializing_if = "is_true")]
    pub photo_reflectance: bool,
    /// Exposure multiplier applied before 8-bit output.
    pub exposure: f64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp_min: 4,
            spp_max: 16,
            seed: 0,
            spectral: false,
            max_depth: 4,
            radiosity: false,
            photo_reflectance: true,
            exposure: 1.0,
        }
    }
}
