//! `cloth cantilever`: the cantilever test (ASTM D1388).

use clap::Args;

use crate::args::*;

#[derive(Args)]
pub(crate) struct CantileverArgs {
    /// The fabric preset (denim, interlock, rib-knit, ponte, sweatshirt, swimsuit,
    /// polyester, tablecloth, jacket, twill).
    #[arg(long, required_unless_present = "all")]
    pub(crate) fabric: Option<String>,
    /// Every preset.
    #[arg(long)]
    pub(crate) all: bool,
    /// The models, comma separated: xpbd, mass-spring.
    #[arg(long, value_delimiter = ',', default_values_t = [String::from("xpbd"), String::from("mass-spring")])]
    pub(crate) models: Vec<String>,
    /// Grid spacings in mm, comma separated (2.5 is the default resolution: 11
    /// particles across the strip).
    #[arg(long, value_delimiter = ',', default_values_t = [2.5])]
    pub(crate) spacing: Vec<f32>,
    /// Prints one JSON object a line instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
}

pub(crate) fn cantilever(args: CantileverArgs) -> Result<(), String> {
    use bevy_cloth_lab::cantilever::{self, StripModel};
    let fabrics = chosen_fabrics(&args.fabric, args.all)?;
    let models = args
        .models
        .iter()
        .map(|m| match m.as_str() {
            "xpbd" => Ok(StripModel::Xpbd),
            "mass-spring" => Ok(StripModel::MassSpring),
            other => Err(format!("no model `{other}` here; known: xpbd, mass-spring")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(s) = args.spacing.iter().find(|s| !(0.5..=12.5).contains(*s)) {
        return Err(format!("a spacing of {s} mm; from 0.5 to 12.5 mm"));
    }
    if !args.json {
        println!(
            "| fabric | model | spacing mm | expected c mm | clamped: overhang mm | c mm | error | ledge: overhang mm | c mm | error | elastica overhang mm |"
        );
        println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    }
    for (name, fabric) in &fabrics {
        for &model in &models {
            for &mm in &args.spacing {
                let m = cantilever::measure(name, *fabric, model, mm * 1e-3)?;
                if args.json {
                    println!("{}", serde_json::to_string(&m).map_err(|e| e.to_string())?);
                } else {
                    println!(
                        "| {} | {:?} | {mm} | {:.2} | {:.2} | {:.2} | {:+.1}% | {:.2} | {:.2} | {:+.1}% | {:.2} |",
                        m.fabric,
                        m.model,
                        m.expected * 1e3,
                        m.overhang * 1e3,
                        m.measured * 1e3,
                        m.error * 100.0,
                        m.ledge_overhang * 1e3,
                        m.ledge_measured * 1e3,
                        m.ledge_error * 100.0,
                        m.elastica_overhang * 1e3,
                    );
                }
            }
        }
    }
    Ok(())
}
