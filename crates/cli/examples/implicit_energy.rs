//! What implicit Euler's numerical damping costs: the total energy of the
//! stiff cloth-128 curtain of `animats bench implicit` over its 10 s, with
//! symplectic Euler at its largest stable step and implicit Euler at two
//! steps, with and without the curtain's linear drag. Writes two PNGs.
//!
//! `cargo run --release -p animats --example implicit_energy -- docs/img/implicit_energy`
//! (writes `…_drag.png` and `…_no_drag.png`; about two minutes).

use animats_bench::stiff::{leg, stable_symplectic, Leg, CURTAIN_DRAG};
use animats_engine::IntegratorKind;
use animats_render::{step_plot_png, Plot, Series};

fn series(l: &Leg) -> Series {
    Series {
        label: format!("{} at {:.3e} s", l.kind, l.h),
        points: l.energy.clone(),
    }
}

fn main() -> Result<(), String> {
    let prefix = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "implicit_energy".into());
    let n = 128;
    for (drag, name, title) in [
        (CURTAIN_DRAG, "drag", "with linear drag (b = 1e-3 N s/m)"),
        (0.0, "no_drag", "without drag"),
    ] {
        let legs = [
            stable_symplectic(n, drag),
            leg(n, drag, IntegratorKind::Implicit, 0.1),
            leg(n, drag, IntegratorKind::Implicit, 1.0),
        ];
        for l in &legs {
            let (e0, e1) = (l.energy[0].1, l.energy[l.energy.len() - 1].1);
            println!(
                "{name}: {} at {:.3e} s: E {e0:.4} -> {e1:.4} J, {:.2} s wall, centre of mass y {:.4} m",
                l.kind, l.h, l.seconds, l.com.y
            );
        }
        let plot = Plot {
            title: format!("Stiff cloth-128 curtain {title}: total energy"),
            x_label: "time, s".into(),
            y_label: "kinetic + spring + gravitational energy, J".into(),
            series: legs.iter().map(series).collect(),
            size: (900, 600),
        };
        let out = format!("{prefix}_{name}.png");
        let png = step_plot_png(&plot)?;
        std::fs::write(&out, png).map_err(|e| format!("{out}: {e}"))?;
        println!("wrote {out}");
    }
    Ok(())
}
