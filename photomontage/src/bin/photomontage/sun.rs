//! `photomontage sun`: solar position (NREL SPA) and sunrise/sunset for a site and an instant.

use anyhow::{Context, Result, bail};
use chrono::{DateTime, FixedOffset, SecondsFormat};
use photomontage::sun::{self, SpaParams};

/// Arguments of `photomontage sun`.
#[derive(clap::Args, Debug)]
pub struct SunArgs {
    /// Latitude in degrees, north positive.
    #[arg(long, allow_negative_numbers = true)]
    lat: f64,
    /// Longitude in degrees, east positive.
    #[arg(long, allow_negative_numbers = true)]
    lon: f64,
    /// Instant as RFC 3339, e.g. 2003-10-17T12:30:30-07:00; outputs use the same offset.
    #[arg(long)]
    time: String,
    /// Site elevation above sea level, metres.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    elevation_m: f64,
    /// Annual mean pressure, millibars.
    #[arg(long, default_value_t = 1013.25)]
    pressure_mbar: f64,
    /// Annual mean temperature, °C.
    #[arg(long, default_value_t = 12.0, allow_negative_numbers = true)]
    temperature_c: f64,
    /// ΔT = TT − UT1 in seconds (about 69 s in 2025).
    #[arg(long, default_value_t = 69.0, allow_negative_numbers = true)]
    delta_t_s: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(args: &SunArgs) -> Result<()> {
    let time: DateTime<FixedOffset> =
        DateTime::parse_from_rfc3339(&args.time).with_context(|| {
            format!(
                "cannot parse --time {:?} as RFC 3339 (e.g. 2003-10-17T12:30:30-07:00)",
                args.time
            )
        })?;
    if !(-90.0..=90.0).contains(&args.lat) {
        bail!("--lat {} is outside −90…90 degrees", args.lat);
    }
    if !(-180.0..=180.0).contains(&args.lon) {
        bail!("--lon {} is outside −180…180 degrees", args.lon);
    }
    let params = SpaParams {
        elevation_m: args.elevation_m,
        pressure_mbar: args.pressure_mbar,
        temperature_c: args.temperature_c,
        delta_t_s: args.delta_t_s,
        ..SpaParams::at(args.lat, args.lon)
    };
    let position = sun::solar_position(&time, &params).context("solar position")?;
    let rts = sun::sun_rise_transit_set(time.date_naive(), time.offset(), &params)
        .context("sunrise/sunset")?;
    let fmt = |t: &DateTime<FixedOffset>| t.to_rfc3339_opts(SecondsFormat::Secs, true);
    let sunrise = rts.sunrise.as_ref().map(fmt);
    let sunset = rts.sunset.as_ref().map(fmt);
    let transit = fmt(&rts.transit);
    let omega = sun::sun_solid_angle_sr(
        position.earth_sun_distance_au * sun::astronomical_unit_m(),
        sun::SUN_RADIUS_M,
    )?;
    if args.json {
        let out = serde_json::json!({
            "time": time.to_rfc3339_opts(SecondsFormat::AutoSi, true),
            "zenith_deg": position.zenith_deg,
            "azimuth_deg": position.azimuth_deg,
            "elevation_deg": position.elevation_deg,
            "geometric_zenith_deg": position.geometric_zenith_deg,
            "sunrise": sunrise,
            "transit": transit,
            "sunset": sunset,
            "julian_day": position.julian_day,
            "equation_of_time_min": position.equation_of_time_min,
            "earth_sun_distance_au": position.earth_sun_distance_au,
            "sun_solid_angle_sr": omega,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("time           {}", time.to_rfc3339());
        println!("zenith         {:.6}°", position.zenith_deg);
        println!(
            "azimuth        {:.6}° (east of north)",
            position.azimuth_deg
        );
        println!("elevation      {:.6}°", position.elevation_deg);
        println!("sunrise        {}", sunrise.as_deref().unwrap_or("none"));
        println!("transit        {transit}");
        println!("sunset         {}", sunset.as_deref().unwrap_or("none"));
        println!("sun distance   {:.6} AU", position.earth_sun_distance_au);
        println!("sun Ω          {omega:.4e} sr");
    }
    Ok(())
}
