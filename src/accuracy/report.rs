//! A sweep written for the user: `accuracy.csv` (a row per setting), `accuracy.json`
//! (the same with the quantities no setting brings under the target
//! and the recommendation), `pareto.png` (worst error
//! against the time to the scene's end, the front joined) and `convergence.png`
//! (each error against the time step at the scene's regularisation and meshes).

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use super::errors::Quantity;
use super::sweep::Sweep;
use crate::Real;
use crate::output::plot::{LogChart, PointSet};

/// Colours of the quantities in the convergence plot (Tableau 10).
const COLOURS: [(u8, u8, u8); 8] = [
    (31, 119, 180),
    (214, 39, 40),
    (44, 160, 44),
    (255, 127, 14),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (23, 190, 207),
];

/// Writes the four files into `dir` (created if missing).
pub fn write(sweep: &Sweep, dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("accuracy.csv"), csv(sweep))?;
    let json = serde_json::to_string_pretty(&Json::of(sweep)).map_err(io::Error::other)?;
    std::fs::write(dir.join("accuracy.json"), json + "\n")?;
    pareto_chart(sweep).write_png(&dir.join("pareto.png"))?;
    convergence_chart(sweep).write_png(&dir.join("convergence.png"))
}

/// A row per setting: the knobs, each error (empty where not measured), the
/// worst counted, the cost, and the marks.
pub fn csv(sweep: &Sweep) -> String {
    let mut out = String::from("dt_fraction,dt,regularisation,skin,mesh_step,faces");
    for q in Quantity::ALL {
        let _ = write!(out, ",{}", q.name());
    }
    out += ",worst_counted,particles,contacts,particle_steps_per_second,contacts_per_second,\
            seconds_to_end,pareto,recommended\n";
    for (i, p) in sweep.points.iter().enumerate() {
        let s = &p.settings;
        let opt = |v: Option<String>| v.unwrap_or_default();
        let _ = write!(
            out,
            "{},{:e},{},{:e},{},{}",
            s.dt_fraction,
            p.dt,
            s.regularisation,
            s.skin,
            opt(s.mesh.map(|m| m.to_string())),
            opt(p.faces.map(|f| f.to_string()))
        );
        for q in Quantity::ALL {
            let _ = write!(out, ",{}", opt(p.errors.get(q).map(|e| format!("{e:e}"))));
        }
        let c = &p.cost;
        let _ = writeln!(
            out,
            ",{:e},{},{:.1},{:.4e},{:.4e},{:.4e},{},{}",
            sweep.counted_error(i),
            c.particles,
            c.contacts,
            c.particle_steps_per_second,
            c.contacts_per_second,
            c.seconds_to_end,
            p.pareto,
            sweep.recommended == Some(i)
        );
    }
    out
}

/// `accuracy.json`.
#[derive(serde::Serialize)]
struct Json<'a> {
    target: Real,
    base: &'a super::Settings,
    unmet: &'a [super::sweep::Unmet],
    recommended: Option<&'a super::sweep::Point>,
    points: &'a [super::sweep::Point],
}

impl<'a> Json<'a> {
    fn of(sweep: &'a Sweep) -> Self {
        Json {
            target: sweep.target,
            base: &sweep.base,
            unmet: &sweep.unmet,
            recommended: sweep.recommended.map(|i| &sweep.points[i]),
            points: &sweep.points,
        }
    }
}

fn colour(k: usize) -> plotters::style::RGBColor {
    let (r, g, b) = COLOURS[k % COLOURS.len()];
    plotters::style::RGBColor(r, g, b)
}

/// Worst counted error against the time to the scene's end; the front joined.
pub fn pareto_chart(sweep: &Sweep) -> LogChart {
    let point = |i: usize| (sweep.points[i].cost.seconds_to_end, sweep.counted_error(i));
    let n = sweep.points.len();
    let mut front: Vec<(f64, f64)> = (0..n)
        .filter(|&i| sweep.points[i].pareto)
        .map(point)
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut chart = LogChart::new(
        "Speed against error: every setting swept",
        "wall-clock time to the scene's end (s)",
        "largest relative error (targeted quantities)",
    );
    chart.sets.push(PointSet {
        name: "settings".into(),
        points: (0..n).map(point).collect(),
        colour: colour(0),
        joined: false,
        marker: 4,
    });
    chart.sets.push(PointSet {
        name: "Pareto front".into(),
        points: front,
        colour: colour(1),
        joined: true,
        marker: 5,
    });
    if let Some(i) = sweep.recommended {
        chart.sets.push(PointSet {
            name: "recommended".into(),
            points: vec![point(i)],
            colour: colour(2),
            joined: false,
            marker: 9,
        });
    }
    chart
        .levels
        .push((format!("target {}", percent(sweep.target)), sweep.target));
    chart
}

/// Each error against the time step, at the scene's own regularisation, skin and
/// meshes.
pub fn convergence_chart(sweep: &Sweep) -> LogChart {
    let b = &sweep.base;
    let at_base: Vec<_> = sweep
        .points
        .iter()
        .filter(|p| {
            let s = &p.settings;
            s.regularisation == b.regularisation && s.skin == b.skin && s.mesh == b.mesh
        })
        .collect();
    let mut chart = LogChart::new(
        "Errors against the time step",
        "time step over the suggested one (1)",
        "relative error (1)",
    );
    chart.headroom = 0.45;
    for (k, q) in Quantity::ALL.iter().enumerate() {
        let mut points: Vec<(f64, f64)> = at_base
            .iter()
            .filter_map(|p| p.errors.get(*q).map(|e| (p.settings.dt_fraction, e)))
            .collect();
        if points.is_empty() {
            continue;
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart.sets.push(PointSet {
            name: q.name().into(),
            points,
            colour: colour(k),
            joined: true,
            marker: 3,
        });
    }
    chart
}

/// `0.02` as `2 %`.
pub fn percent(x: Real) -> String {
    format!("{} %", 100.0 * x)
}
