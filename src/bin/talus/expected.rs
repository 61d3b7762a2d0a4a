//! The errors to expect of a scene's settings, as `talus check` and `talus run`
//! state them: the reference impacts of `talus::accuracy` at the scene's time step.

use std::fmt::Write;

use talus::Real;
use talus::accuracy::{Feature, Impact, impact_speed, impacts};
use talus::engine::RoundLaw;
use talus::output::ImpactSummary;
use talus::scene::Scene;

/// The scene's reference impacts (milliseconds to seconds: one contact each).
pub fn measure(scene: &Scene) -> Vec<Impact> {
    impacts(scene, impact_speed(scene))
}

/// The impacts as lines of text, one per particle kind and wall material.
pub fn describe(scene: &Scene, found: &[Impact]) -> String {
    let Some(first) = found.first() else {
        return String::new();
    };
    let materials = &scene.world.materials;
    let mut text = format!(
        "expected errors at dt = {:.4e} s (one impact of each kind at {:.3} m/s: restitution \
         realised against requested, and the impact's energy account):\n",
        scene.dt, first.speed
    );
    let mut rest = found;
    while let Some(head) = rest.first() {
        let n = rest
            .iter()
            .take_while(|i| i.kind == head.kind && i.material == head.material)
            .count();
        let (group, tail) = rest.split_at(n);
        let _ = write!(
            text,
            "  {} ({}) on {}: e = {:.3}:",
            name(scene, head.kind),
            materials[scene.world.body_types[head.kind].material].name,
            materials[head.material].name,
            head.requested
        );
        for i in group {
            let _ = write!(
                text,
                " {} {:+.2} %",
                i.feature.name(),
                100.0 * i.restitution_error()
            );
        }
        let worst = group
            .iter()
            .map(|i| i.energy_error.abs())
            .fold(0.0, Real::max);
        let _ = writeln!(text, "; energy account within {:.2} %", 100.0 * worst);
        rest = tail;
    }
    if let RoundLaw::HertzMindlin { .. } = scene.step_params().round_law
        && found.iter().any(|i| i.feature == Feature::Sphere)
    {
        text.push_str(
            "  (Hertz–Mindlin's damping realises a restitution of its own, above the one \
             asked for, as in LIGGGHTS and EDEM)\n",
        );
    }
    text
}

/// The impacts as `summary.json` lists them.
pub fn summarise(scene: &Scene, found: &[Impact]) -> Vec<ImpactSummary> {
    let materials = &scene.world.materials;
    found
        .iter()
        .map(|i| ImpactSummary {
            kind: name(scene, i.kind),
            wall_material: materials[i.material].name.clone(),
            feature: i.feature.name().into(),
            speed: i.speed,
            requested: i.requested,
            realised: i.realised,
            restitution_error: i.restitution_error(),
            energy_error: i.energy_error,
        })
        .collect()
}

/// The shape name of particle kind `kind`.
fn name(scene: &Scene, kind: usize) -> String {
    scene
        .shape_names
        .get(kind)
        .cloned()
        .unwrap_or_else(|| format!("kind {kind}"))
}
