//! SIFT keypoints, ratio-tested mutual matches, fundamental-matrix RANSAC per pair, tracks
//! (the steps of the module doc of [`super`]).

use std::path::PathBuf;

use image::{GrayImage, imageops::FilterType};
use nalgebra::Point2;
use opencv::core::{self, DMatch, KeyPoint, Mat, Point2f, Vector};
use opencv::prelude::*;
use opencv::{calib3d, features2d};
use serde::Serialize;

use super::tracks::{PairMatches, build_tracks};
use super::{FeatureError, MatchOptions};
use crate::photo::{self, DecodeLimits, PhotoImage, Transfer};

/// One photo to match.
#[derive(Debug, Clone)]
pub struct MatchInput {
    pub id: String,
    pub path: PathBuf,
}

/// Keypoints of one photo (full-resolution pixels, pixel-centre convention of
/// [`crate::camera`]).
#[derive(Debug, Clone, Serialize)]
pub struct PhotoFeatures {
    pub id: String,
    pub keypoints: usize,
    /// Full-resolution pixels per detection pixel.
    pub detection_scale: f64,
    #[serde(skip)]
    pub pixels: Vec<Point2<f64>>,
    #[serde(skip)]
    descriptors: Mat,
}

/// Counts of one pair, step by step.
#[derive(Debug, Clone, Serialize)]
pub struct PairStats {
    pub photo_a: String,
    pub photo_b: String,
    /// Matches passing the ratio test (a → b).
    pub ratio_passed: usize,
    /// Of those, the mutual ones.
    pub mutual: usize,
    /// Of those, the RANSAC inliers of the fundamental matrix (0 when fewer than the minimum).
    pub verified: usize,
}

/// One track: (photo index, full-resolution pixel) per photo that sees it.
#[derive(Debug, Clone, Serialize)]
pub struct Track {
    pub observations: Vec<(usize, Point2<f64>)>,
}

/// Everything [`match_photos`] found.
#[derive(Debug, Clone, Serialize)]
pub struct MatchReport {
    pub photos: Vec<PhotoFeatures>,
    pub pairs: Vec<PairStats>,
    pub tracks: Vec<Track>,
    /// Candidate tracks with two keypoints in one photo (dropped).
    pub conflicts_dropped: usize,
}

/// 8-bit BT.601 luma of the sRGB-encoded photo, downscaled to at most `max_side` pixels.
fn detection_image(image: &PhotoImage, max_side: u32) -> (GrayImage, f64) {
    let [w, h] = image.size_px();
    let encode = |v: f32| -> f32 {
        match image.transfer {
            Transfer::Srgb => v,
            // Linear (EXR) values: the sRGB transfer curve, so contrast matches a JPEG's.
            Transfer::Linear => {
                let v = v.clamp(0.0, 1.0);
                if v <= 0.003_130_8 {
                    12.92 * v
                } else {
                    1.055 * v.powf(1.0 / 2.4) - 0.055
                }
            }
        }
    };
    let gray = GrayImage::from_fn(w, h, |x, y| {
        let p = image.pixels.get_pixel(x, y).0;
        let luma = 0.299 * encode(p[0]) + 0.587 * encode(p[1]) + 0.114 * encode(p[2]);
        // Round to the nearest 8-bit level; the clamp keeps the cast in range.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let level = (luma * 255.0).round().clamp(0.0, 255.0) as u8;
        image::Luma([level])
    });
    let longer = w.max(h);
    if longer <= max_side {
        return (gray, 1.0);
    }
    let scale = f64::from(longer) / f64::from(max_side);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (sw, sh) = (
        (f64::from(w) / scale).round().max(1.0) as u32,
        (f64::from(h) / scale).round().max(1.0) as u32,
    );
    let small = image::imageops::resize(&gray, sw, sh, FilterType::Triangle);
    (small, f64::from(w) / f64::from(sw))
}

fn to_mat(gray: &GrayImage) -> Result<Mat, FeatureError> {
    let rows = i32::try_from(gray.height())
        .map_err(|_| FeatureError::Geometry("image too tall".into()))?;
    let flat = Mat::from_slice(gray.as_raw())?;
    let shaped = flat.reshape(1, rows)?;
    Ok(shaped.try_clone()?)
}

/// SIFT keypoints and descriptors of one photo.
fn detect(
    input: &MatchInput,
    options: &MatchOptions,
    limits: &DecodeLimits,
) -> Result<PhotoFeatures, FeatureError> {
    let image = photo::load_with_limits(&input.path, limits)?;
    let (gray, scale) = detection_image(&image, options.max_image_side_px);
    drop(image);
    let mat = to_mat(&gray)?;
    let nfeatures = i32::try_from(options.max_features).unwrap_or(i32::MAX);
    let mut sift = features2d::SIFT::create(nfeatures, 3, 0.04, 10.0, 1.6)?;
    let mut keypoints = Vector::<KeyPoint>::new();
    let mut descriptors = Mat::default();
    sift.detect_and_compute(
        &mat,
        &core::no_array(),
        &mut keypoints,
        &mut descriptors,
        false,
    )?;
    if keypoints.is_empty() {
        return Err(FeatureError::NoKeypoints {
            photo: input.id.clone(),
        });
    }
    // Detection pixel centre (x + 0.5)·s − 0.5 in the full image (both pixel-centre frames).
    let pixels = keypoints
        .iter()
        .map(|k| {
            let p = k.pt();
            Point2::new(
                (f64::from(p.x) + 0.5) * scale - 0.5,
                (f64::from(p.y) + 0.5) * scale - 0.5,
            )
        })
        .collect::<Vec<_>>();
    Ok(PhotoFeatures {
        id: input.id.clone(),
        keypoints: pixels.len(),
        detection_scale: scale,
        pixels,
        descriptors,
    })
}

/// Ratio-tested nearest neighbours of every descriptor of `query` in `train`: index pairs.
fn ratio_matches(
    query: &Mat,
    train: &Mat,
    ratio: f64,
) -> Result<Vec<(usize, usize)>, FeatureError> {
    let matcher = features2d::BFMatcher::create(core::NORM_L2, false)?;
    let mut knn = Vector::<Vector<DMatch>>::new();
    matcher.knn_train_match(query, train, &mut knn, 2, &core::no_array(), false)?;
    let mut out = Vec::new();
    for pair in &knn {
        if pair.len() < 2 {
            continue;
        }
        let (best, second) = (pair.get(0)?, pair.get(1)?);
        if f64::from(best.distance) < ratio * f64::from(second.distance) {
            out.push((
                usize::try_from(best.query_idx).unwrap_or(usize::MAX),
                usize::try_from(best.train_idx).unwrap_or(usize::MAX),
            ));
        }
    }
    Ok(out)
}

/// Matches of one pair: ratio test both ways, mutual check, fundamental-matrix RANSAC.
fn match_pair(
    a: &PhotoFeatures,
    b: &PhotoFeatures,
    options: &MatchOptions,
) -> Result<(PairStats, Vec<(usize, usize)>), FeatureError> {
    let forward = ratio_matches(&a.descriptors, &b.descriptors, options.ratio)?;
    let backward = ratio_matches(&b.descriptors, &a.descriptors, options.ratio)?;
    let best_of_b: std::collections::HashMap<usize, usize> = backward.iter().copied().collect();
    let mutual: Vec<(usize, usize)> = forward
        .iter()
        .copied()
        .filter(|&(ia, ib)| best_of_b.get(&ib) == Some(&ia))
        .collect();
    let mut stats = PairStats {
        photo_a: a.id.clone(),
        photo_b: b.id.clone(),
        ratio_passed: forward.len(),
        mutual: mutual.len(),
        verified: 0,
    };
    if mutual.len() < options.min_pair_matches.max(8) {
        return Ok((stats, Vec::new()));
    }
    let to_cv = |p: &Point2<f64>| {
        #[allow(clippy::cast_possible_truncation)]
        Point2f::new(p.x as f32, p.y as f32)
    };
    let pts_a: Vector<Point2f> = mutual.iter().map(|&(i, _)| to_cv(&a.pixels[i])).collect();
    let pts_b: Vector<Point2f> = mutual.iter().map(|&(_, j)| to_cv(&b.pixels[j])).collect();
    core::set_rng_seed(i32::try_from(options.seed % (i32::MAX as u64)).unwrap_or(0))?;
    let mut mask = Mat::default();
    let f = calib3d::find_fundamental_mat(
        &pts_a,
        &pts_b,
        calib3d::FM_RANSAC,
        options.epipolar_threshold_px,
        0.999,
        10_000,
        &mut mask,
    )?;
    if f.empty() {
        return Ok((stats, Vec::new()));
    }
    let inlier = mask.data_bytes()?;
    let verified: Vec<(usize, usize)> = mutual
        .iter()
        .zip(inlier)
        .filter(|(_, m)| **m != 0)
        .map(|(p, _)| *p)
        .collect();
    stats.verified = verified.len();
    if verified.len() < options.min_pair_matches {
        return Ok((stats, Vec::new()));
    }
    Ok((stats, verified))
}

/// Detects, matches and verifies features in every pair of `inputs` and joins the matches into
/// tracks.
///
/// # Errors
/// Invalid options, fewer than two photos, a photo that cannot be decoded or has no
/// keypoints, a photo that shares no verified matches with any other ([`FeatureError::NoOverlap`]
/// names it and its best partner), OpenCV failures.
pub fn match_photos(
    inputs: &[MatchInput],
    options: &MatchOptions,
    limits: &DecodeLimits,
) -> Result<MatchReport, FeatureError> {
    options.validate()?;
    if inputs.len() < 2 {
        return Err(FeatureError::TooFewPhotos {
            found: inputs.len(),
        });
    }
    let photos = inputs
        .iter()
        .map(|i| detect(i, options, limits))
        .collect::<Result<Vec<_>, _>>()?;
    let mut pairs = Vec::new();
    let mut verified = Vec::new();
    for a in 0..photos.len() {
        for b in a + 1..photos.len() {
            let (stats, matches) = match_pair(&photos[a], &photos[b], options)?;
            pairs.push(stats);
            if !matches.is_empty() {
                verified.push(PairMatches {
                    photo_a: a,
                    photo_b: b,
                    matches,
                });
            }
        }
    }
    for (i, p) in photos.iter().enumerate() {
        let linked = verified.iter().any(|m| m.photo_a == i || m.photo_b == i);
        if !linked {
            let best = pairs
                .iter()
                .filter(|s| s.photo_a == p.id || s.photo_b == p.id)
                .max_by_key(|s| (s.verified, s.mutual));
            let (best_other, best_matches) = best.map_or((String::new(), 0), |s| {
                let other = if s.photo_a == p.id {
                    &s.photo_b
                } else {
                    &s.photo_a
                };
                (other.clone(), s.verified)
            });
            return Err(FeatureError::NoOverlap {
                photo: p.id.clone(),
                best_other,
                best_matches,
                required: options.min_pair_matches,
            });
        }
    }
    let counts: Vec<usize> = photos.iter().map(|p| p.pixels.len()).collect();
    let set = build_tracks(&counts, &verified)?;
    let tracks = set
        .tracks
        .iter()
        .map(|nodes| Track {
            observations: nodes
                .iter()
                .map(|n| (n.photo, photos[n.photo].pixels[n.keypoint]))
                .collect(),
        })
        .collect();
    Ok(MatchReport {
        photos,
        pairs,
        tracks,
        conflicts_dropped: set.conflicts_dropped,
    })
}
