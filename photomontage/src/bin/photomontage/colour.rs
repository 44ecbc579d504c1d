//! `photomontage colour`: what a designer's colour is in the renderer's terms: sRGB hex, linear
//! reflectance, CIE L*a*b* and LCh (D65), the nearest RAL Design code, and the light reflectance
//! value (LRV), with the sRGB gamut flagged; with two colours, their LRV difference.

use anyhow::{Result, bail};
use photomontage::colour::designer::{
    ColourSpec, hex_from_linear, lch_from_lab, parse_colour, xyz_from_lab,
};
use photomontage::colour::ral_design::RalDesign;

/// Arguments of `photomontage colour`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Colours as the site file takes them: `#a0522d`, `lab(52.2, 30.1, 42.7)`,
    /// `lch(52.2, 52.2, 54.8)` or a RAL Design code `RAL 210 50 15` (quote each).
    #[arg(required = true, num_args = 1..)]
    colours: Vec<String>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(args: &Args) -> Result<()> {
    let mut specs = Vec::with_capacity(args.colours.len());
    for text in &args.colours {
        match parse_colour(text) {
            Ok(spec) => specs.push((text.as_str(), spec)),
            Err(e) => bail!("{e}"),
        }
    }
    let rows: Vec<serde_json::Value> = specs.iter().map(|(text, spec)| row(text, spec)).collect();
    let lrv_difference = (specs.len() == 2).then(|| {
        let l = |s: &ColourSpec| s.resolve().lrv;
        (l(&specs[0].1) - l(&specs[1].1)).abs()
    });
    if args.json {
        let mut out = serde_json::json!({ "colours": rows });
        if let Some(d) = lrv_difference {
            out["lrv_difference"] = d.into();
        }
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    for r in &rows {
        let f = |k: &str, i: usize| r[k][i].as_f64().unwrap_or(f64::NAN);
        println!("{}", r["input"].as_str().unwrap_or_default());
        println!("  hex        {}", r["hex"].as_str().unwrap_or_default());
        println!(
            "  linear RGB {:.4} {:.4} {:.4}",
            f("linear_rgb", 0),
            f("linear_rgb", 1),
            f("linear_rgb", 2)
        );
        println!(
            "  L*a*b*     {:.2} {:.2} {:.2} (D65)",
            f("lab", 0),
            f("lab", 1),
            f("lab", 2)
        );
        println!(
            "  LCh        {:.2} {:.2} {:.2}",
            f("lch", 0),
            f("lch", 1),
            f("lch", 2)
        );
        println!(
            "  RAL Design {}",
            r["nearest_ral_design"]
                .as_str()
                .unwrap_or("none (L* or C* needs three digits)")
        );
        println!("  LRV        {:.1}", r["lrv"].as_f64().unwrap_or(f64::NAN));
        if r["out_of_gamut"].as_bool() == Some(true) {
            eprintln!(
                "warning: {} is outside the sRGB gamut; the renderer clamps it to {}",
                r["input"].as_str().unwrap_or_default(),
                r["hex"].as_str().unwrap_or_default()
            );
        }
    }
    if let Some(d) = lrv_difference {
        println!("LRV difference {d:.1} points");
    }
    Ok(())
}

/// One colour's values (the clamped reflectance the renderer uses).
fn row(text: &str, spec: &ColourSpec) -> serde_json::Value {
    let resolved = spec.resolve();
    let lab = spec.lab();
    serde_json::json!({
        "input": text,
        "hex": hex_from_linear(resolved.linear_rgb),
        "linear_rgb": resolved.linear_rgb,
        "lab": lab,
        "lch": lch_from_lab(lab),
        "nearest_ral_design": RalDesign::nearest(xyz_from_lab(lab)).map(|c| c.to_string()),
        "lrv": resolved.lrv,
        "out_of_gamut": resolved.out_of_gamut,
    })
}
