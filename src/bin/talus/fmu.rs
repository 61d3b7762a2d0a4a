//! `talus fmu`: pack a scene as an FMU.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use talus::fmi::description::FmiVersion;
use talus::fmi::package::{write_fmu, write_remote_fmu};
use talus::fmi::remote_spec::RemoteSpec;

/// The shared library next to the running program (`target/<profile>/libtalus.so`).
fn default_library() -> Result<PathBuf> {
    let exe = std::env::current_exe().context("cannot locate the talus program")?;
    let lib = exe.with_file_name("libtalus.so");
    if !lib.is_file() {
        bail!(
            "no shared library at {}: build it with `cargo build --release` (it is built with \
             the talus program) or give --library",
            lib.display()
        );
    }
    Ok(lib)
}

pub fn fmu(
    scene: &Path,
    output: &Path,
    fmi: u8,
    library: Option<PathBuf>,
    remote: Option<RemoteSpec>,
) -> Result<()> {
    let library = match library {
        Some(l) => l,
        None if remote.is_some() && !cfg!(feature = "zenoh") => bail!(
            "--remote: this talus was built without the zenoh feature, so its library cannot \
             forward calls to a node (cargo build --release --features zenoh, or give --library)"
        ),
        None => default_library()?,
    };
    let version = if fmi == 3 {
        FmiVersion::Three
    } else {
        FmiVersion::Two
    };
    let summary = match &remote {
        None => write_fmu(scene, &library, version, output),
        Some(remote) => write_remote_fmu(scene, &library, version, output, remote),
    }
    .with_context(|| format!("cannot pack {}", scene.display()))?;
    println!(
        "{}: FMI {fmi}.0 co-simulation FMU, {} variables, guid {}, {} resource file(s), {:.1} MB",
        output.display(),
        summary.variables,
        summary.guid,
        summary.resources.len(),
        summary.bytes as f64 / 1e6
    );
    if let Some(remote) = &remote {
        println!(
            "its instances forward every call to the talus node '{}'{} (start it with `talus \
             serve {} --key {}`, or under mpirun), waiting at most {} s for each answer",
            remote.key,
            if remote.connect.is_empty() {
                " found by multicast scouting".to_string()
            } else {
                format!(" at {}", remote.connect.join(", "))
            },
            scene.display(),
            remote.key,
            remote.timeout
        );
    }
    if !summary.left_out.is_empty() {
        println!(
            "note: FMI 2.0 has no arrays; left out: {} (FMI 3.0, the C API and zenoh carry \
             them; fluid grids of at most {} cells are offered as FMI 2.0 scalars)",
            summary.left_out.join(", "),
            talus::cosim::variables::FMI2_MAX_FLUID_CELLS
        );
    }
    Ok(())
}
