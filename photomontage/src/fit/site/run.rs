//! The fits proper on the located samples (Durisch 1992 §4.2–4.3): the horizon colour L∞ from
//! the `[[horizon_samples]]`, the atmosphere (eq. 7) and the daylight weights (eq. 9), repeated
//! with the gathered interreflection (in the radiosity mode: read off the photographed state's
//! radiosity solution) until the weights settle, the sun/shadow cross-checks
//! against the SPA, and the check that a fit's samples share one material.

use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use nalgebra::{Point3, Vector3};

use crate::atmosphere::schachter::true_radiance;
use crate::fit::FitObserver;
use crate::fit::atmosphere::{AtmosphereFit, fit_atmosphere_robust};
use crate::fit::colour::{ColourReadOptions, read_rect};
use crate::fit::daylight::{
    DaylightFit, DaylightFitOptions, DaylightSample, fit_daylight, irradiance_components,
    normalised_sky_facets,
};
use crate::fit::interreflection::{
    GatherPoint, INTERREFLECTION_MAX_PASSES, INTERREFLECTION_SETTLED_REL, gather_interreflection,
    scene_with_probe, weights_settled,
};
use crate::fit::radiosity_interreflection::RadiosityInterreflection;
use crate::fit::report::{FitResidual, NamedSunCheck, SampleReading, SiteFitReport};
use crate::fit::sun_check::check_sun;
use crate::scene::{Material, MaterialLibrary, Scene, SceneTracer};
use crate::site::render::{site_sky_model, site_sun_dir};
use crate::site::{SamplePurpose, Site, SiteDocument};
use crate::sky_dome::durisch_facets::durisch_dome;

use super::{
    Located, Photos, REPORT_REFERENCE_DISTANCE_M, SiteFitError, SiteFitOptions, check_cancel,
    photo_time, spa_params,
};

pub(super) fn horizon(
    site: &Site,
    horizons: &[&crate::site::HorizonSample],
    photos: &mut Photos<'_>,
    warnings: &mut Vec<String>,
) -> ([f64; 3], Option<[f64; 3]>) {
    let mut reads = Vec::new();
    for h in horizons {
        let read = photos.get(&h.photo).and_then(|p| {
            read_rect(
                p,
                [i64::from(h.origin_px[0]), i64::from(h.origin_px[1])],
                h.size_px,
                &ColourReadOptions::default(),
            )
            .map_err(|e| e.to_string())
        });
        match read {
            Ok(r) => reads.push(r.linear_rgb),
            Err(e) => warnings.push(format!("horizon sample `{}` not used: {e}", h.id)),
        }
    }
    if reads.is_empty() {
        warnings.push(
            "no usable horizon sample: L∞ taken from [lighting.atmosphere].horizon_colour".into(),
        );
        return (site.lighting.atmosphere.horizon_colour, None);
    }
    #[allow(clippy::cast_precision_loss)]
    let n = reads.len() as f64;
    let mean = [0, 1, 2].map(|k| reads.iter().map(|r| r[k]).sum::<f64>() / n);
    let sigma = (reads.len() > 1).then(|| {
        [0, 1, 2].map(|k| {
            (reads.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        })
    });
    (mean, sigma)
}

pub(super) fn sun_checks(
    doc: &SiteDocument,
    options: &SiteFitOptions,
    warnings: &mut Vec<String>,
) -> Vec<NamedSunCheck> {
    let site = &doc.site;
    let coords = |id: &str| -> Option<Point3<f64>> {
        site.control_points
            .iter()
            .find(|c| c.id == id)
            .map(|c| c.xyz)
            .or_else(|| site.tie_points.iter().find(|t| t.id == id).map(|t| t.xyz))
            .map(Point3::from)
    };
    let mut out = Vec::new();
    for pair in &site.sun_shadow_pairs {
        let (Some(object), Some(shadow)) = (coords(&pair.object_point), coords(&pair.shadow_point))
        else {
            warnings.push(format!(
                "sun check `{}` skipped: a point has no coordinates yet (run `solve`)",
                pair.id
            ));
            continue;
        };
        let Some(time) = photo_time(doc, &pair.photo) else {
            warnings.push(format!(
                "sun check `{}` skipped: photo `{}` has no taken_at or EXIF time",
                pair.id, pair.photo
            ));
            continue;
        };
        let Some((params, convergence)) = spa_params(site) else {
            warnings.push(format!(
                "sun check `{}` skipped: the site has no [location]",
                pair.id
            ));
            continue;
        };
        match check_sun(
            object,
            shadow,
            &time,
            &params,
            convergence,
            options.sun_tolerance_deg,
        ) {
            Ok(check) => {
                warnings.extend(check.warning(&pair.id));
                out.push(NamedSunCheck {
                    pair: pair.id.clone(),
                    check,
                });
            }
            Err(e) => warnings.push(format!("sun check `{}` failed: {e}", pair.id)),
        }
    }
    out
}

#[allow(clippy::too_many_lines)]
pub(super) fn run_fits(
    doc: &SiteDocument,
    scene: &Scene,
    located: &[Located],
    horizons: &[&crate::site::HorizonSample],
    photos: &mut Photos<'_>,
    tracer: &SceneTracer,
    options: &SiteFitOptions,
    observer: Option<Arc<dyn FitObserver>>,
    warnings: &mut Vec<String>,
    library: Option<&MaterialLibrary>,
) -> Result<SiteFitReport, SiteFitError> {
    let site = &doc.site;
    let (horizon_colour, horizon_colour_sigma) = horizon(site, horizons, photos, warnings);
    let atm_samples: Vec<&Located> = located
        .iter()
        .filter(|s| s.purpose == SamplePurpose::Atmosphere)
        .collect();
    let day_samples: Vec<&Located> = located
        .iter()
        .filter(|s| s.purpose == SamplePurpose::Daylight)
        .collect();
    let mut residuals = Vec::new();
    // Atmosphere (eq. 7), or the site's current one.
    let atmosphere: Option<AtmosphereFit> = if atm_samples.is_empty() {
        warnings.push(
            "no atmosphere samples: the atmosphere is kept from [lighting.atmosphere]".into(),
        );
        None
    } else {
        one_material("atmosphere", &atm_samples)?;
        let data: Vec<(f64, [f64; 3])> = atm_samples
            .iter()
            .map(|s| (s.distance_m, s.apparent))
            .collect();
        let fit = fit_atmosphere_robust(
            horizon_colour,
            &data,
            REPORT_REFERENCE_DISTANCE_M,
            site.solve.outlier_threshold_sigma,
            observer.clone(),
        )
        .map_err(|source| SiteFitError::Atmosphere {
            samples: id_list(&atm_samples),
            source,
        })?;
        for (k, clamped) in fit.clamped.iter().enumerate() {
            if *clamped {
                warnings.push(format!(
                    "atmosphere samples {} get more contrast with distance in channel {k}: τ clamped to 1 (clear air)",
                    id_list(&atm_samples)
                ));
            }
        }
        for ((s, r), flagged) in atm_samples.iter().zip(&fit.residuals).zip(&fit.flagged) {
            residuals.push(FitResidual {
                sample: s.id.clone(),
                fit: "atmosphere",
                residual_rgb: *r,
                normalised: None,
                flagged: *flagged,
            });
        }
        let dropped: Vec<&Located> = atm_samples
            .iter()
            .zip(&fit.flagged)
            .filter(|(_, f)| **f)
            .map(|(s, _)| *s)
            .collect();
        if !dropped.is_empty() {
            warnings.push(format!(
                "atmosphere samples dropped as outliers (normalised residual > {}): {}",
                site.solve.outlier_threshold_sigma,
                id_list(&dropped)
            ));
        }
        Some(fit)
    };
    let extinction_per_m = atmosphere.as_ref().map_or(
        site.lighting.atmosphere.extinction_per_m,
        AtmosphereFit::extinction_per_m,
    );
    // Daylight (eq. 9).
    let mut gathered: HashMap<String, [f64; 3]> = HashMap::new();
    let daylight: Option<DaylightFit> = if day_samples.is_empty() {
        warnings.push("no daylight samples: the weights in [lighting] are kept".into());
        None
    } else {
        let rho_of = |s: &Located| {
            library
                .and_then(|l| l.get(&s.material))
                .map(Material::diffuse_reflectance_rgb)
        };
        let several = day_samples
            .iter()
            .any(|s| s.material != day_samples[0].material);
        if several && let Some(s) = day_samples.iter().find(|s| rho_of(s).is_none()) {
            return Err(SiteFitError::NoReflectance {
                sample: s.id.clone(),
                material: s.material.clone(),
            });
        }
        let sun_dir = site_sun_dir(doc, &day_samples[0].photo)
            .map(|d| (d.z > 0.0).then_some(d))
            .map_err(|e| SiteFitError::Sun(e.to_string()))?;
        if sun_dir.is_none() {
            warnings.push("the sun is below the horizon: only ambient and sky are fitted".into());
        }
        let dome = durisch_dome(options.sky_m_h).map_err(|e| SiteFitError::Sun(e.to_string()))?;
        let sky_sun = sun_dir.unwrap_or_else(Vector3::z);
        let model = site_sky_model(doc, &day_samples[0].photo, &sky_sun)
            .map_err(|e| SiteFitError::Sun(e.to_string()))?;
        let sky = normalised_sky_facets(&dome, &model, &sky_sun).map_err(|source| {
            SiteFitError::Daylight {
                samples: id_list(&day_samples),
                source,
            }
        })?;
        let mut samples: Vec<DaylightSample> = day_samples
            .iter()
            .map(|s| DaylightSample {
                id: s.id.clone(),
                // Eq. 8 with d in metres and the extinction per metre (dₐ = 1 m).
                true_colour_rgb: [0, 1, 2].map(|k| {
                    true_radiance(
                        s.apparent[k],
                        horizon_colour[k],
                        (-extinction_per_m[k]).exp(),
                        s.distance_m,
                        1.0,
                    )
                }),
                components: irradiance_components(
                    tracer,
                    &s.point,
                    &s.normal,
                    sun_dir.as_ref(),
                    &sky,
                ),
                normal_in_world: s.normal,
                diffuse_reflectance_rgb: rho_of(s),
                interreflection_rgb: [0.0; 3],
            })
            .collect();
        let fit_options = DaylightFitOptions {
            outlier_threshold: site.solve.outlier_threshold_sigma,
            diffuse_reflectance_rgb: None,
            fit_ambient: site.fit_settings.ambient,
        };
        let absolute = samples.iter().all(|s| s.diffuse_reflectance_rgb.is_some());
        let gather = site.fit_settings.interreflection && absolute;
        if site.fit_settings.interreflection && !absolute {
            warnings.push(
                "interreflection is not subtracted: it needs the samples' diffuse reflectance"
                    .into(),
            );
        }
        // E_r depends on the weights only through surfaces the photos do not show (shaded by
        // their library material): refit with the fitted weights until they settle.
        let mut gather_doc = doc.clone();
        gather_doc.site.lighting.atmosphere.extinction_per_m = extinction_per_m;
        gather_doc.site.lighting.atmosphere.horizon_colour = horizon_colour;
        let probe_scene = if gather && !doc.site.render.radiosity {
            Some(
                scene_with_probe(scene)
                    .map_err(|e| SiteFitError::Interreflection(e.to_string()))?,
            )
        } else {
            None
        };
        // In the radiosity mode E_r comes from the photographed state's radiosity solution,
        // solved once with the first pass's weights (that pass fits without E_r) and relit to
        // each later pass's, its surfaces' reflectances read off the photos under that pass's
        // weights where `[render] photo_reflectance` asks for them
        // (`fit::radiosity_interreflection`).
        let radiosity = gather && doc.site.render.radiosity;
        let points: Vec<GatherPoint<'_>> = day_samples
            .iter()
            .map(|s| GatherPoint {
                photo: &s.photo,
                point_in_world_m: s.point,
                normal_in_world: s.normal,
            })
            .collect();
        let mut solved: Option<RadiosityInterreflection> = None;
        let mut previous: Option<DaylightFit> = None;
        let mut passes = 0_usize;
        let fit = loop {
            check_cancel(observer.as_ref())?;
            passes += 1;
            if radiosity {
                if passes > 1 {
                    let interreflection = match &mut solved {
                        Some(r) => r,
                        None => solved.insert(
                            RadiosityInterreflection::build(
                                &gather_doc,
                                scene,
                                &points,
                                &AtomicBool::new(false),
                            )
                            .map_err(|e| SiteFitError::Interreflection(e.to_string()))?,
                        ),
                    };
                    let e_r = interreflection
                        .at(&gather_doc)
                        .map_err(|e| SiteFitError::Interreflection(e.to_string()))?;
                    for (s, e) in samples.iter_mut().zip(e_r) {
                        s.interreflection_rgb = e;
                    }
                }
            } else if let Some(probe_scene) = &probe_scene {
                let e_r = gather_interreflection(
                    &gather_doc,
                    probe_scene,
                    &points,
                    options.sky_m_h,
                    options.interreflection_m_h,
                    |id| photos.get(id).map(crate::render::linear_photo),
                )
                .map_err(|e| SiteFitError::Interreflection(e.to_string()))?;
                for (s, e) in samples.iter_mut().zip(e_r) {
                    s.interreflection_rgb = e;
                }
            }
            let fit = fit_daylight(&samples, &fit_options, observer.clone()).map_err(|source| {
                SiteFitError::Daylight {
                    samples: id_list(&day_samples),
                    source,
                }
            })?;
            let settled = previous.as_ref().is_some_and(|p| weights_settled(p, &fit));
            if !gather || settled || passes >= INTERREFLECTION_MAX_PASSES {
                if gather && !settled {
                    warnings.push(format!(
                        "the daylight weights changed by more than {INTERREFLECTION_SETTLED_REL} \
                         between the last two interreflection passes"
                    ));
                }
                break fit;
            }
            let l = &mut gather_doc.site.lighting;
            l.sun_weight = fit.sun_weight;
            l.ambient_weight = fit.ambient_weight;
            l.sky_weight = fit.sky_weight;
            previous = Some(fit);
        };
        if gather {
            for s in &samples {
                gathered.insert(s.id.clone(), s.interreflection_rgb);
            }
        }
        if fit.relative {
            warnings.push(format!(
                "material `{}` has no diffuse reflectance in the material library: the weights \
                 are relative (ρ_d = 1 assumed, Durisch §4.3)",
                day_samples[0].material
            ));
        }
        warnings.extend(fit.warnings.iter().cloned());
        for r in &fit.residuals {
            residuals.push(FitResidual {
                sample: r.sample.clone(),
                fit: "daylight",
                residual_rgb: r.residual_rgb,
                normalised: Some(r.normalised),
                flagged: r.flagged,
            });
        }
        Some(fit)
    };
    Ok(SiteFitReport {
        transmittance: atmosphere.as_ref().map(|a| a.transmittance),
        transmittance_sigma: atmosphere.as_ref().map(|a| a.transmittance_sigma),
        reference_distance_m: REPORT_REFERENCE_DISTANCE_M,
        horizon_colour,
        horizon_colour_sigma,
        sun_weight: daylight.as_ref().map(|d| d.sun_weight),
        sun_weight_sigma: daylight.as_ref().map(|d| d.sun_weight_sigma),
        ambient_weight: daylight.as_ref().map(|d| d.ambient_weight),
        ambient_weight_sigma: daylight.as_ref().map(|d| d.ambient_weight_sigma),
        sky_weight: daylight.as_ref().map(|d| d.sky_weight),
        sky_weight_sigma: daylight.as_ref().map(|d| d.sky_weight_sigma),
        weights_relative: daylight.as_ref().is_some_and(|d| d.relative),
        residuals,
        warnings: Vec::new(),
        sun_checks: Vec::new(),
        samples: located
            .iter()
            .map(|s| SampleReading {
                id: s.id.clone(),
                point_in_world_m: s.point.into(),
                distance_m: s.distance_m,
                apparent_rgb: s.apparent,
                rejected_px: s.rejected_px,
                interreflection_rgb: gathered.get(&s.id).copied(),
            })
            .collect(),
        extinction_per_m: atmosphere.as_ref().map(AtmosphereFit::extinction_per_m),
    })
}

fn one_material(fit: &'static str, samples: &[&Located]) -> Result<(), SiteFitError> {
    if let Some(first) = samples.first()
        && let Some(other) = samples.iter().find(|s| s.material != first.material)
    {
        return Err(SiteFitError::MixedMaterials {
            fit,
            sample: other.id.clone(),
            material: other.material.clone(),
            first: first.id.clone(),
            expected: first.material.clone(),
        });
    }
    Ok(())
}

fn id_list(samples: &[&Located]) -> String {
    samples
        .iter()
        .map(|s| format!("`{}`", s.id))
        .collect::<Vec<_>>()
        .join(", ")
}
