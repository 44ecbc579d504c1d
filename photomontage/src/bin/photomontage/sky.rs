//! `photomontage sky`: a CIE standard general sky's E_h/L_z and fisheye luminance map.

use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use photomontage::sky::{self, SkyModel};
use std::path::PathBuf;

/// Arguments of `photomontage sky`.
#[derive(clap::Args, Debug)]
pub struct SkyArgs {
    /// CIE S 011 standard sky type, 1…15.
    #[arg(long = "type")]
    sky_type: u8,
    /// Sun elevation above the horizon, degrees.
    #[arg(long, allow_negative_numbers = true)]
    sun_elevation_deg: f64,
    /// Sun azimuth east of north, degrees.
    #[arg(long, allow_negative_numbers = true)]
    sun_azimuth_deg: f64,
    /// Write a fisheye luminance map (PNG) here.
    #[arg(long)]
    map: Option<PathBuf>,
    /// Map width and height in pixels.
    #[arg(long, default_value_t = 512)]
    map_size_px: u32,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(args: &SkyArgs) -> Result<()> {
    let model = SkyModel::cie_general(args.sky_type).context("--type")?;
    if !(-90.0..=90.0).contains(&args.sun_elevation_deg) {
        bail!(
            "--sun-elevation-deg {} is outside −90…90",
            args.sun_elevation_deg
        );
    }
    if !args.sun_azimuth_deg.is_finite() {
        bail!("--sun-azimuth-deg must be a finite number");
    }
    let sun: Vector3<f64> = sky::direction_from_elevation_azimuth(
        args.sun_elevation_deg.to_radians(),
        args.sun_azimuth_deg.to_radians(),
    );
    let ratio = model.horizontal_illuminance_over_zenith_luminance(&sun);
    if let Some(path) = &args.map {
        let img = sky::map::sky_map(&model, &sun, args.map_size_px).context("sky map")?;
        img.save(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if args.json {
        let out = serde_json::json!({
            "type": args.sky_type,
            "sun_elevation_deg": args.sun_elevation_deg,
            "sun_azimuth_deg": args.sun_azimuth_deg,
            "horizontal_illuminance_over_zenith_luminance": ratio,
            "map": args.map.as_ref().map(|p| p.display().to_string()),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("CIE standard sky type {}", args.sky_type);
        println!(
            "sun            elevation {}°, azimuth {}°",
            args.sun_elevation_deg, args.sun_azimuth_deg
        );
        println!("E_h/L_z        {ratio:.6}");
        if let Some(path) = &args.map {
            println!("map            {}", path.display());
        }
    }
    Ok(())
}
