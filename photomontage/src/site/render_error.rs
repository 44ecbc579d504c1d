//! What can go wrong turning a site into a render job, and the warnings that do not stop it.

use std::fmt;

use serde::Serialize;

use crate::atmosphere::schachter::AtmosphereError;
use crate::photo::PhotoError;
use crate::scene::SceneError;
use crate::sky_dome::DomeError;
use crate::sun::SunError;

/// What can go wrong turning a site into a render job.
#[derive(Debug, thiserror::Error)]
pub enum SiteRenderError {
    #[error("no photo `{id}` in the site; valid view ids: {}", valid.join(", "))]
    UnknownView { id: String, valid: Vec<String> },
    #[error("photo {photo} is not solved; run `photomontage solve` first")]
    NotSolved { photo: String },
    #[error(
        "photo {photo} has an exterior but no interior with image_size_px; run `photomontage solve` again"
    )]
    NoInterior { photo: String },
    #[error("polygon `{polygon}`: vertex `{point}` is neither a control point nor a tie point")]
    UnknownPoint { polygon: String, point: String },
    #[error("polygon `{polygon}`: {source}")]
    Polygon { polygon: String, source: SceneError },
    #[error("[[materials]] `{material}`: {reason}; nothing written")]
    SiteMaterial { material: String, reason: String },
    #[error("material library {path}: {source}")]
    MaterialLibrary {
        path: String,
        source: crate::scene::material::MaterialError,
    },
    #[error("model `{model}` ({path}): {source}")]
    Model {
        model: String,
        path: String,
        source: SceneError,
    },
    #[error(
        "no visible model in the site: nothing to render (add a [[models]] entry or make one visible)"
    )]
    NoVisibleModel,
    #[error(
        "no sun direction for photo `{photo}`: {reason}; set lighting.sun_manual, or lighting.time \
         (or photos.taken_at) and [location]"
    )]
    NoSunDirection { photo: String, reason: String },
    #[error("location.time_zone: {0}")]
    TimeZone(crate::time_zone::TimeZoneError),
    #[error("sun position: {0}")]
    Sun(#[from] SunError),
    #[error("sky: {reason}")]
    Sky { reason: String },
    #[error("sky dome: {0}")]
    Dome(#[from] DomeError),
    #[error("lighting.atmosphere: {reason}")]
    AtmosphereSetting { reason: String },
    #[error("lighting.atmosphere: {0}")]
    Atmosphere(#[from] AtmosphereError),
    #[error(transparent)]
    Photo(#[from] PhotoError),
    #[error("photo `{photo}` is {photo_px:?} px but its camera images {camera_px:?} px")]
    SizeMismatch {
        photo: String,
        photo_px: [u32; 2],
        camera_px: [u32; 2],
    },
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
    #[error("luminaire `{luminaire}` ({path}): {reason}")]
    LuminaireFile {
        luminaire: String,
        path: String,
        reason: String,
    },
    #[error("luminaire `{luminaire}`: {field} {reason}")]
    LuminaireSetting {
        luminaire: String,
        field: &'static str,
        reason: String,
    },
    /// A render request the renderer cannot take (checked before anything loads).
    #[error("{field}: {reason}")]
    Request { field: &'static str, reason: String },
    #[error(transparent)]
    Tracer(#[from] crate::render::DifferentialError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    #[error(transparent)]
    Spectral(#[from] crate::render::SpectralError),
}

/// Something worth telling the user that does not stop the render.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SiteWarning {
    /// Polygons name a material the library does not have (or there is no library); they get
    /// [`DEFAULT_POLYGON_ALBEDO`].
    MissingMaterial {
        material: String,
        polygons: Vec<String>,
    },
    /// A CAD model's size is implausible (outside [`SCALE_WARNING_MIN_EXTENT_M`],
    /// [`SCALE_WARNING_MAX_EXTENT_M`]).
    ModelScale { model: String, extent_m: f64 },
    /// An importer warning, rendered as text.
    Import { model: String, message: String },
    /// A render setting of the site was adjusted to what the renderer accepts.
    Setting { message: String },
    /// A luminaire that will not light as the user probably meant (e.g. zero scale).
    Luminaire { luminaire: String, message: String },
    /// A site material (`[[materials]]`) was clamped or matches nothing in the scene.
    SiteMaterial { material: String, message: String },
}

impl fmt::Display for SiteWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingMaterial { material, polygons } => write!(
                f,
                "material `{material}` is not in the material library; polygons {} use the \
                 default diffuse reflectance 0.5",
                polygons.join(", ")
            ),
            Self::ModelScale { model, extent_m } => write!(
                f,
                "model `{model}` is {extent_m:.4} m across: check its units and placement.scale"
            ),
            Self::Import { model, message } => write!(f, "model `{model}`: {message}"),
            Self::Setting { message } => f.write_str(message),
            Self::Luminaire { luminaire, message } => {
                write!(f, "luminaire `{luminaire}`: {message}")
            }
            Self::SiteMaterial { material, message } => {
                write!(f, "[[materials]] `{material}`: {message}")
            }
        }
    }
}
