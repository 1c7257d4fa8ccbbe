//! `cloth drape`: the drape test (Cusick).

use clap::Args;

use crate::args::*;
use crate::charts;

#[derive(Args)]
pub(crate) struct DrapeArgs {
    /// The fabric preset.
    #[arg(long, required_unless_present = "all")]
    pub(crate) fabric: Option<String>,
    /// Every preset.
    #[arg(long)]
    pub(crate) all: bool,
    /// Grid spacing in mm (at 10 mm the coefficient is off by up to 0.06 from its value at
    /// 7.5 and 5 mm).
    #[arg(long, default_value_t = 5.0)]
    pub(crate) spacing: f32,
    #[command(flatten)]
    pub(crate) output: Output,
}

pub(crate) fn drape(args: DrapeArgs) -> Result<(), String> {
    let fabrics = chosen_fabrics(&args.fabric, args.all)?;
    if !(2.5..=30.0).contains(&args.spacing) {
        return Err(format!(
            "a spacing of {} mm; from 2.5 to 30 mm",
            args.spacing
        ));
    }
    if !args.output.json {
        println!(
            "| fabric | bending length mm | B µN·m | drape coefficient (mean of 5) | least–most |"
        );
        println!("|---|---:|---:|---:|---:|");
    }
    let mut drapes = Vec::new();
    for (name, fabric) in &fabrics {
        let xpbd = bevy_cloth::params::Model::Xpbd(bevy_cloth::params::XpbdParams {
            tethers: false,
            ..Default::default()
        });
        let d = bevy_cloth_lab::drape::drape(name, *fabric, args.spacing * 1e-3, xpbd)?;
        if args.output.json {
            println!("{}", serde_json::to_string(&d).map_err(|e| e.to_string())?);
        } else {
            println!(
                "| {} | {:.1} | {:.2} | {:.3} | {:.3}–{:.3} |",
                d.fabric,
                d.bending_length * 1e3,
                fabric.bending * 1e6,
                d.coefficient,
                d.spread.0,
                d.spread.1
            );
        }
        drapes.push(d);
    }
    if let Some(png) = &args.output.chart {
        charts::drape(png, &drapes)?;
    }
    Ok(())
}
