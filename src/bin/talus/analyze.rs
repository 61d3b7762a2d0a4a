//! `talus analyze OUT_DIR`: the packing analysis of a run's final state, and the
//! same at the end of `talus run` for scenes with a `[bed]` section.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use talus::analysis::packing::{Bed, analyse, porosity_map};
use talus::output::packing::{
    read_poses, write_bed_stl, write_mesher_beds, write_packing, write_porosity_map, write_poses,
};
use talus::scene::Scene;
use talus::world::World;

/// Analyses `world`'s bed and writes the packing files (and the poses) into `dir`;
/// prints the main figures.
pub fn write_bed_files(scene: &Scene, bed: &Bed, world: &World, dir: &Path) -> Result<()> {
    // Files list the particles by id, whatever the order they are stored in.
    let world = &*world.in_id_order();
    write_poses(dir, world, &scene.shape_names)?;
    let shrink = scene.spec.bed.as_ref().map_or(1.0, |b| b.shrink);
    write_bed_stl(dir, world, shrink)?;
    write_mesher_beds(dir, world, bed)?;
    let packing = analyse(world, bed).map_err(|e| anyhow!("packing analysis: {e}"))?;
    write_packing(dir, &packing)?;
    let map = porosity_map(world, bed, &packing).map_err(|e| anyhow!("porosity map: {e}"))?;
    write_porosity_map(dir, &map)?;
    println!(
        "bed: {} particles, height {:.4e} m, porosity {:.4} over {:.4e}–{:.4e} m (N = {:.2}), \
         mean coordination {:.2}; packing.json in {}",
        packing.particles,
        packing.bed_height,
        packing.porosity,
        packing.region[0],
        packing.region[1],
        packing.tube_to_particle,
        packing.coordination_mean,
        dir.display()
    );
    Ok(())
}

/// `talus analyze OUT_DIR`: reads the scene named in `summary.json` and the final
/// poses of `poses.csv`.
pub fn analyze(dir: &Path) -> Result<()> {
    let summary_path = dir.join("summary.json");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&summary_path)
            .with_context(|| format!("cannot read {}", summary_path.display()))?,
    )
    .with_context(|| format!("{} is not JSON", summary_path.display()))?;
    let scene_path = summary["scene"]
        .as_str()
        .ok_or_else(|| anyhow!("{}: no \"scene\" field", summary_path.display()))?;
    let scene = Scene::load(Path::new(scene_path))?;
    let Some(bed) = scene.bed else {
        bail!("{scene_path}: the scene has no [bed] section to analyse");
    };
    let mut world = scene.world.clone();
    read_poses(&dir.join("poses.csv"), &mut world).map_err(|e| anyhow!(e))?;
    write_bed_files(&scene, &bed, &world, dir)
}
