//! Locating the site's colour samples on the natural scene (a world point, or the ray through a
//! pixel of its photo's solved camera) and reading their colour robustly from the photo
//! ([`crate::fit::colour`]).

use nalgebra::{Point2, Point3, Vector3};

use crate::fit::colour::read_window;
use crate::scene::{Scene, SceneTracer};
use crate::site::{SiteDocument, stored_camera};

use super::{Located, POINT_ON_POLYGON_M, Photos, SiteFitOptions};

pub(super) fn locate_sample(
    doc: &SiteDocument,
    sample: &crate::site::Sample,
    scene: &Scene,
    tracer: &SceneTracer,
    photos: &mut Photos<'_>,
    options: &SiteFitOptions,
    warnings: &mut Vec<String>,
) -> Result<Located, String> {
    let id = &sample.id;
    let camera = stored_camera(&doc.site, &sample.photo)
        .ok_or_else(|| format!("photo `{}` has no solved camera", sample.photo))?;
    let centre = camera.pose.camera_center_in_world;
    let (pixel, dir) = match (sample.point, sample.x_px, sample.y_px) {
        (Some(p), _, _) => {
            let p = Point3::from(p);
            let pixel = camera
                .project(&p)
                .ok_or_else(|| format!("point is behind the camera of photo `{}`", sample.photo))?;
            (pixel, (p - centre).normalize())
        }
        (None, Some(x), Some(y)) => {
            let pixel = Point2::new(x, y);
            (pixel, camera.ray_dir_in_world(pixel))
        }
        _ => return Err("neither `point` nor `x_px`/`y_px` given".into()),
    };
    let ray = tracer.ray_from_world(&centre, &dir, 0.0, f32::INFINITY);
    let hit = tracer.closest_hit(&ray).ok_or_else(|| {
        format!(
            "not on any polygon: the ray through ({:.1}, {:.1}) px of photo `{}` hits nothing",
            pixel.x, pixel.y, sample.photo
        )
    })?;
    let mut point = tracer.hit_point_in_world_m(&ray, hit.hit.t);
    let n = hit.hit.normal_geometric;
    let mut normal = Vector3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2])).normalize();
    if normal.dot(&dir) > 0.0 {
        normal = -normal;
    }
    if let Some(p) = sample.point {
        let p = Point3::from(p);
        let off_plane_m = (p - point).dot(&normal);
        let limit = POINT_ON_POLYGON_M.max(1e-3 * (point - centre).norm());
        if off_plane_m.abs() > limit {
            return Err(format!(
                "the point is not on a polygon visible in photo `{}`: the line of sight meets a \
                 polygon {:.2} m from it",
                sample.photo,
                (point - p).norm()
            ));
        }
        // The given point moved along the normal onto the polygon's plane: not the f32 hit
        // (which a grazing ray moves along the surface), and not the point itself (survey noise
        // puts it up to `limit` behind the surface, where shadow and gather rays would start
        // inside the object).
        point = p - normal * off_plane_m;
    }
    let material = scene
        .materials()
        .get(hit.material.0 as usize)
        .map_or("", |m| m.name.as_str());
    if material != sample.material {
        return Err(format!(
            "lies on a polygon of material `{material}`, not `{}`",
            sample.material
        ));
    }
    let photo = photos.get(&sample.photo)?;
    let read = read_window(photo, [pixel.x, pixel.y], sample.window_px, &options.colour)
        .map_err(|e| format!("colour at ({:.1}, {:.1}) px: {e}", pixel.x, pixel.y))?;
    if read.saturated_px + read.underexposed_px > 0 {
        warnings.push(format!(
            "sample `{id}`: {} saturated and {} underexposed pixels of its window rejected",
            read.saturated_px, read.underexposed_px
        ));
    }
    Ok(Located {
        id: id.clone(),
        material: sample.material.clone(),
        purpose: sample.purpose,
        photo: sample.photo.clone(),
        point,
        normal,
        distance_m: (point - centre).norm(),
        apparent: read.linear_rgb,
        rejected_px: [read.saturated_px, read.underexposed_px],
    })
}
