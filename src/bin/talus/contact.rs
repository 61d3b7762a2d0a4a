//! `talus contact`: the contact of two bodies from a small TOML file.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use talus::geometry::Shape;
use talus::geometry::ShapeSpec;
use talus::geometry::gjk::{GjkResult, gjk};
use talus::geometry::overlap::overlap;
use talus::geometry::sphere::{sphere_polyhedron, sphere_sphere};

use super::print_shape;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PairFile {
    body: Vec<Body>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Body {
    name: String,
    shape: ShapeSpec,
    #[serde(default)]
    position: [f64; 3],
    /// Rotation vector (axis times angle, radians).
    #[serde(default)]
    rotation: [f64; 3],
}

pub fn contact(file: &Path) -> Result<()> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("cannot read {}", file.display()))?;
    let pair: PairFile =
        toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    if pair.body.len() != 2 {
        bail!(
            "{}: expected exactly two [[body]] entries, found {}",
            file.display(),
            pair.body.len()
        );
    }
    let base = file.parent().unwrap_or(Path::new("."));
    let mut bodies = Vec::new();
    for b in &pair.body {
        let shape = b
            .shape
            .build(base)
            .with_context(|| format!("{}: body '{}'", file.display(), b.name))?;
        // A mesh's body frame is its principal frame; the file gives the pose of the
        // mesh's own frame.
        let input_frame = Isometry3::from_parts(
            Translation3::from(Vector3::from(b.position)),
            UnitQuaternion::from_scaled_axis(Vector3::from(b.rotation)),
        );
        let pose = match &shape {
            Shape::Polyhedron(p) => input_frame * p.body_to_input(),
            Shape::Sphere(_) => input_frame,
        };
        print_shape(&b.name, &shape);
        bodies.push((shape, pose));
    }
    let (a, pa) = &bodies[0];
    let (b, pb) = &bodies[1];
    let rel = pa.inverse() * pb;
    println!(
        "contact of '{}' with '{}':",
        pair.body[0].name, pair.body[1].name
    );
    match (a, b) {
        (Shape::Polyhedron(pa_shape), Shape::Polyhedron(pb_shape)) => {
            let g = gjk(pa_shape.as_ref(), pb_shape.as_ref(), &rel, None);
            match g {
                GjkResult::Intersecting => println!("  GJK                     intersecting"),
                GjkResult::Separated { distance, .. } => {
                    println!("  GJK                     apart by {distance:.6e} m")
                }
            }
            match overlap(pa_shape, pb_shape, &rel) {
                None => println!("  overlap                 none"),
                Some(o) => {
                    let smaller = pa_shape.volume().min(pb_shape.volume());
                    println!(
                        "  overlap volume          {:.6e} m³ ({:.4} % of the smaller body)",
                        o.volume,
                        100.0 * o.volume / smaller
                    );
                    let c = pa * o.centroid;
                    let n = pa * o.normal;
                    println!(
                        "  contact point (world)   [{:.6e}, {:.6e}, {:.6e}] m",
                        c.x, c.y, c.z
                    );
                    println!(
                        "  normal A→B (world)      [{:.6}, {:.6}, {:.6}]",
                        n.x, n.y, n.z
                    );
                    println!("  projected contact area  {:.6e} m²", o.area);
                    println!("  depth along the normal  {:.6e} m", o.depth);
                }
            }
            let reps = 20_000;
            let t = Instant::now();
            for _ in 0..reps {
                std::hint::black_box(gjk(
                    pa_shape.as_ref(),
                    pb_shape.as_ref(),
                    std::hint::black_box(&rel),
                    None,
                ));
            }
            let t_gjk = t.elapsed().as_secs_f64() / reps as f64;
            let t = Instant::now();
            for _ in 0..reps {
                std::hint::black_box(overlap(pa_shape, pb_shape, std::hint::black_box(&rel)));
            }
            let t_overlap = t.elapsed().as_secs_f64() / reps as f64;
            println!(
                "  time per evaluation     GJK {:.0} ns, overlap {:.0} ns (one thread, {reps} repeats)",
                t_gjk * 1e9,
                t_overlap * 1e9
            );
        }
        (Shape::Sphere(s1), Shape::Sphere(s2)) => {
            print_sphere_contact(
                sphere_sphere(s1.radius, s2.radius, &rel.translation.vector),
                pa,
            );
        }
        (Shape::Polyhedron(p), Shape::Sphere(s)) => {
            let c = rel.translation.vector.into();
            print_sphere_contact(sphere_polyhedron(p, &c, s.radius), pa);
        }
        (Shape::Sphere(s), Shape::Polyhedron(p)) => {
            let inv = rel.inverse();
            let c = inv.translation.vector.into();
            let contact = sphere_polyhedron(p, &c, s.radius).map(|mut k| {
                k.normal = -(rel * k.normal);
                k.point = rel * k.point;
                k
            });
            print_sphere_contact(contact, pa);
        }
    }
    Ok(())
}

fn print_sphere_contact(c: Option<talus::geometry::sphere::SphereContact>, frame: &Isometry3<f64>) {
    match c {
        None => println!("  no contact"),
        Some(c) => {
            let p = frame * c.point;
            let n = frame * c.normal;
            println!("  depth                   {:.6e} m", c.depth);
            println!("  overlap volume          {:.6e} m³", c.volume);
            println!(
                "  contact point (world)   [{:.6e}, {:.6e}, {:.6e}] m",
                p.x, p.y, p.z
            );
            println!(
                "  normal A→B (world)      [{:.6}, {:.6}, {:.6}]",
                n.x, n.y, n.z
            );
        }
    }
}
