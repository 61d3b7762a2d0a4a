//! The MPI exchange (feature `mpi`): `examples/mpi_ranks.rs` under `mpirun -np 1`
//! to `4` (more ranks than cores: `--oversubscribe`; as root, with OpenMPI's
//! consent variables) moves every particle of a shaken box as one process does, to
//! the bit, with particles changing rank.
#![cfg(feature = "mpi")]

use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/examples/mpi_ranks`, built with the tests.
fn program() -> PathBuf {
    let deps = std::env::current_exe().unwrap();
    deps.parent()
        .and_then(|d| d.parent())
        .map(|profile| profile.join("examples").join("mpi_ranks"))
        .unwrap()
}

#[test]
fn mpi_ranks_move_every_particle_as_one_process_does() {
    for ranks in 1..=4 {
        let out = Command::new("mpirun")
            .args(["--oversubscribe", "-np", &ranks.to_string()])
            .arg(program())
            .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .expect("mpirun (openmpi-bin) is installed by scripts/test.sh");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{ranks} ranks: {}\n{stdout}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        let line = stdout
            .lines()
            .find(|l| {
                l.starts_with(&format!(
                    "{ranks} ranks: 100 particles moved as one process"
                ))
            })
            .unwrap_or_else(|| panic!("{ranks} ranks: no report in {stdout}"));
        let changed: usize = line
            .split('(')
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .and_then(|s| s.parse().ok())
            .unwrap();
        assert!(ranks == 1 || changed >= 5, "{line}");
    }
}
