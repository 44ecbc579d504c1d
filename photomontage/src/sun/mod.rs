//! The sun: its position by the NREL SPA (Reda & Andreas 2004), sunrise/transit/sunset, and its
//! solid angle (Durisch 1992 §4.1: "calculated from the distance to the sun and the radius of the
//! sun").
//!
//! Directions are given in the local east-north-up frame (x east, y north, z up), which is the
//! project's world frame when the site's survey grid is aligned with true north; azimuths are
//! measured eastward from north.
//!
//! # Known limitations
//! Grid convergence of projected coordinate systems (the angle between grid north and true north)
//! is not applied here; rotate `direction_enu` by it when the world frame is a map grid.

pub mod disc;
pub mod spa;
pub mod spa_tables;

pub use disc::{SUN_RADIUS_M, astronomical_unit_m, sun_angular_radius, sun_solid_angle_sr};
pub use spa::{
    RiseTransitSet, SolarPosition, SpaParams, julian_day, solar_position, solar_position_at_jd,
    sun_rise_transit_set,
};

/// Errors of the sun models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SunError {
    /// A parameter lies outside the range the algorithm accepts.
    #[error("{name} = {value} is outside {min}…{max}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
    },
    /// The SPA is claimed only for the years −2000…6000.
    #[error("year {year} is outside the SPA's validity range −2000…6000")]
    YearOutOfRange {
        /// Year given.
        year: i32,
    },
    /// A date or time that cannot be represented.
    #[error("date or time cannot be represented")]
    InvalidDate,
}
