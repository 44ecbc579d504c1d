//! photomontage: put planned buildings into site photographs accurately enough for
//! planning-permission visual impact studies ("verified views").
//!
//! The method follows Durisch, *Photogrammetry and computer graphics for visual impact analysis in
//! architecture* (ISPRS 1992): a photogrammetric camera model and its inversions, daylight and
//! atmosphere models fitted to the photos, and a differential ray tracer.
//!
//! Frames and units are part of every name: `world_from_camera` maps camera coordinates to world
//! coordinates; `_px` pixels, `_m` metres, `_deg` degrees (radians otherwise).

pub mod atmosphere;
pub mod atomic_file;
pub mod bounded_read;
pub mod bvh;
pub mod calibration;
pub mod camera;
pub mod colour;
pub mod design;
pub mod exchange;
pub mod farm;
pub mod features;
pub mod fit;
pub mod geo;
pub mod luminaire;
pub mod peer_scene;
pub mod photo;
pub mod photogrammetry;
pub mod radiosity;
pub mod render;
pub mod scene;
pub mod site;
pub mod sky;
pub mod sky_dome;
pub mod study;
pub mod sun;
pub mod time_zone;
pub mod verified;
