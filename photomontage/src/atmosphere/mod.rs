//! Atmosphere between the camera and what it sees: Schachter's homogeneous model as used by
//! Durisch 1992 (§3.2 eq. 2, inversions §4.2 eq. 7–8). See [`schachter`].
//!
//! # Known limitations
//! Only the homogeneous, isotropic model of the seed paper; no height-dependent haze, no
//! sun-angle-dependent airlight (see [`schachter`]).

pub mod schachter;

pub use schachter::{AtmosphereError, SchachterAtmosphere};
