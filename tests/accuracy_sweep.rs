//! `talus accuracy`: the errors its reference problems measure converge as the
//! contact model predicts when a knob is turned, and the setting it recommends
//! meets its target when written into the scene and run afresh.

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use talus::Real;
use talus::accuracy::mesh_resolution::mesh_errors;
use talus::accuracy::{Errors, Quantity, Settings, SweepOptions, impact_speed, sweep};
use talus::scene::Scene;

fn settling_box() -> Scene {
    Scene::load(Path::new("examples/settling_box/scene.toml")).unwrap()
}

fn at(scene: &Scene, dt_fraction: Real) -> Scene {
    Settings {
        dt_fraction,
        ..Settings::of(scene)
    }
    .apply(scene)
    .unwrap()
}

/// The sweep's errors at the scene's regularisation, as the step shrinks: the
/// restitution error (the worst impact, a face meeting the floor at the worst phase
/// of a step) falls in proportion to the step, as velocity Verlet resolves a damped
/// contact to first order (measured −11.4, −5.8, −3.0 %); the elastic collision's
/// energy error at least with its square (measured 1.1e-6, 4.3e-8, 9.7e-9).
#[test]
fn errors_fall_with_the_time_step_at_the_order_of_the_integrator() {
    let scene = settling_box();
    let errors: Vec<Errors> = [1.0, 0.5, 0.25]
        .iter()
        .map(|&f| Errors::measure(&at(&scene, f)))
        .collect();
    let series = |q: Quantity| -> Vec<Real> { errors.iter().map(|e| e.get(q).unwrap()).collect() };
    let restitution = series(Quantity::Restitution);
    let energy = series(Quantity::ElasticEnergy);
    for k in 0..2 {
        let ratio = restitution[k] / restitution[k + 1];
        assert!((1.7..2.4).contains(&ratio), "{restitution:?}");
        assert!(energy[k] / energy[k + 1] > 3.0, "{energy:?}");
    }
    assert!(energy[0] < 1e-4, "{energy:?}");
}

/// An icosphere's sagitta falls fourfold per level, and so do its contact force
/// error against the analytic sphere at the scene's impact depth (measured ratios
/// 3.5, 3.9, 4.0 from level 2 to 5) and its elastic rebound error (spin, sideways
/// and speed; 5.9, 4.0, 4.1). At the finest level both are under 1 %.
#[test]
fn icosphere_errors_fall_fourfold_per_level() {
    let scene = Scene::load(Path::new("tests/scenes/icosphere_beads.toml")).unwrap();
    assert_eq!(Settings::mesh_steps(&scene), (5, Some(2)));
    let errors: Vec<(Real, Real)> = (1..5)
        .map(|step| {
            let s = Settings {
                mesh: Some(step),
                ..Settings::of(&scene)
            }
            .apply(&scene)
            .unwrap();
            let e = mesh_errors(&s, impact_speed(&s));
            (e.force.unwrap(), e.collision.unwrap())
        })
        .collect();
    for k in 0..errors.len() - 1 {
        let force = errors[k].0 / errors[k + 1].0;
        let collision = errors[k].1 / errors[k + 1].1;
        assert!((3.0..5.0).contains(&force), "{errors:?}");
        assert!((3.0..7.0).contains(&collision), "{errors:?}");
    }
    assert!(errors[3].0 < 0.01 && errors[3].1 < 0.01, "{errors:?}");
}

/// The static answers hold at any setting: a resting layer weighs its weight on a
/// wall, whatever the wall's triangulation (a patch spanning facet edges is one
/// contact).
#[test]
fn a_resting_layer_weighs_its_weight_on_any_triangulation() {
    let e = Errors::measure(&settling_box());
    assert!(e.get(Quantity::WallWeight).unwrap() < 1e-9, "{e:?}");
    assert!(e.get(Quantity::Triangulation).unwrap() < 1e-6, "{e:?}");
}

/// Deep-merges TOML `patch` into `base`.
fn merge(base: &mut toml::Table, patch: toml::Table) {
    for (k, v) in patch {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(p)) => merge(b, p),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// The recommended setting, pasted into the scene file as printed, loads as a
/// fresh scene whose every targeted error is within the target, and whose own run
/// (the first 40 ms of the pour) keeps its energy account within it too.
#[test]
fn the_recommendation_meets_its_target_on_a_fresh_run() {
    let scene = settling_box();
    let target = 0.02;
    let swept = sweep(
        &scene,
        SweepOptions {
            budget: Duration::from_secs(3),
            target,
        },
        |_, _, _| {},
    )
    .unwrap();
    // The soft PLA (E = 1 MPa) turns a corner contact into a long one: the
    // rigid-body answer is out of reach of every setting, and said so.
    let unmet: Vec<Quantity> = swept.unmet.iter().map(|u| u.quantity).collect();
    let impulse = swept.unmet.iter().find(|u| u.quantity == Quantity::Impulse);
    assert!(
        impulse.is_some_and(|u| !u.knob_sensitive()),
        "{:?}",
        swept.unmet
    );
    // The restitution error falls with the step, and an eighth of it meets 2 %.
    assert!(!unmet.contains(&Quantity::Restitution), "{unmet:?}");
    let i = swept.recommended.expect("a setting meets 2 %");
    let point = &swept.points[i];
    assert!(swept.points.iter().enumerate().all(|(j, p)| {
        swept.counted_error(j) > target || p.cost.seconds_to_end >= point.cost.seconds_to_end
    }));

    let path = Path::new("examples/settling_box/scene.toml");
    let mut table: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
    let patch: toml::Table = point.settings.as_toml(&scene, point.dt).parse().unwrap();
    merge(&mut table, patch);
    let fresh = Scene::parse(&toml::to_string(&table).unwrap(), path).unwrap();
    assert!(
        (fresh.dt / point.dt - 1.0).abs() < 1e-3,
        "{} vs {}",
        fresh.dt,
        point.dt
    );
    let errors = Errors::measure(&fresh);
    for (q, e) in errors.iter() {
        if !unmet.contains(&q) {
            assert!(e <= target, "{} {e}", q.name());
        }
    }
    let mut run = talus::scene::Simulation::new(&fresh);
    let _ = run.advance_to(0.04, |_, _| std::ops::ControlFlow::<()>::Continue(()));
    let account = talus::scene::energy_ledger::EnergyReport::of(&run);
    assert!(account.relative_error.abs() <= target, "{account:?}");
}

/// `talus accuracy` writes its four files: the CSV a row per setting with the
/// Pareto front and one recommendation marked.
#[test]
fn the_command_writes_its_report() {
    let out = std::env::temp_dir().join(format!("talus-accuracy-{}", std::process::id()));
    let status = Command::new(env!("CARGO_BIN_EXE_talus"))
        .args([
            "accuracy",
            "examples/settling_box/scene.toml",
            "--budget",
            "2",
        ])
        .args(["--target", "2%", "--threads", "1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert!(
        status.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&status.stderr)
    );
    assert!(stdout.contains("recommended"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("accuracy.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows[0].starts_with("dt_fraction,dt,regularisation,skin"));
    assert_eq!(rows.len(), 1 + 14, "{csv}");
    assert!(rows[1..].iter().any(|r| r.ends_with(",true,true")));
    assert_eq!(rows[1..].iter().filter(|r| r.ends_with(",true")).count(), 1);
    for png in ["pareto.png", "convergence.png"] {
        let bytes = std::fs::read(out.join(png)).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("accuracy.json")).unwrap()).unwrap();
    assert_eq!(json["points"].as_array().unwrap().len(), 14);
    let _ = std::fs::remove_dir_all(&out);
}
