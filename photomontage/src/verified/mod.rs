//! Verified views: what a planning authority receives besides the montage itself (Landscape
//! Institute, *Technical Guidance Note 06/19: Visual Representation of Development Proposals*,
//! 2019, Type 4 "photomontage/photowire, survey/scale verifiable", its Appendix 1 methodology and
//! photograph/photomontage information templates; Greater London Authority, *London View
//! Management Framework SPG*, 2012, Appendix C "Accurate Visual Representations" AVR0–AVR3).
//!
//! - [`geometry`]: the view geometry report of a solved photo (camera position, bearing, pitch,
//!   roll, fields of view, 35 mm equivalent, sun at capture, residuals, distance to the proposal,
//!   viewing distance);
//! - [`paper`]: sheet paper sizes and the printed image size the viewing distance follows from;
//! - [`measure`]: ground below the camera, nearest point and centroid of the proposal;
//! - [`avr`]: the AVR0–AVR3 render modes (silhouette, wireline, massing, full montage);
//! - [`wireline`]: the proposal's feature edges with hidden-line removal;
//! - [`planar_view`]: a photo re-projected to a standard (50 mm, 75 mm) focal length;
//! - [`cylindrical_view`]: a panorama from several photos taken from one point;
//! - [`reprojected_geometry`]: the view geometry of planar and cylindrical views;
//! - [`standard_view`]: any of these views with the proposal at an AVR level, and its geometry;
//! - [`view_metadata`], [`xmp`], [`tiff_ifd`] and [`image_metadata`]: the view geometry carried by
//!   output images (EXIF and XMP in JPEG, PNG and TIFF; header attributes in EXR);
//! - [`sheet`] (with [`sheet::html`]) and [`sheet_content`]: the sheet as PDF or HTML (view at print
//!   scale, viewing distance, ruler, geometry table, map inset, AVR level, methodology and
//!   residuals).
//!
//! # Known limitations
//! See each module.

pub mod avr;
pub mod comparison_sheet;
pub mod cylindrical_view;
pub mod geometry;
pub mod image_metadata;
pub mod measure;
pub mod paper;
pub mod planar_view;
pub mod reprojected_geometry;
pub mod sheet;
pub mod sheet_content;
pub mod standard_view;
pub mod tiff_ifd;
pub mod view_metadata;
pub mod wireline;
pub mod xmp;

pub use avr::{AvrLevel, AvrOverlay, apply_massing, avr_overlay};
pub use geometry::{
    ViewGeometry, ViewGeometryError, ViewGeometryOptions, ViewProjection, view_geometry,
};
pub use paper::PaperSize;
pub use view_metadata::ViewMetadata;
