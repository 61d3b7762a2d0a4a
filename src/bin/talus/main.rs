//! The `talus` command line.

mod accuracy;
mod analyze;
mod bench;
#[cfg(feature = "mpi")]
mod bench_ranks;
mod bench_shapes;
mod checkpoint;
mod contact;
mod expected;
mod fmu;
mod launch;
mod run;
mod run_outputs;
#[cfg(feature = "zenoh")]
mod serve;

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Parser, Subcommand};
use talus::geometry::{Shape, ShapeSpec};

#[derive(Parser)]
#[command(
    name = "talus",
    version,
    about = "Polyhedral discrete element method engine"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a scene file and print what will be computed.
    Check {
        /// The scene (TOML).
        scene: PathBuf,
    },
    /// Run a scene: progress, ParaView series, walls.csv, series.csv, summary.json;
    /// checkpoints with [output] checkpoint_interval or --checkpoint-every (and when
    /// interrupted), from which --resume continues.
    Run {
        /// The scene (TOML); with --resume, the checkpoint's scene by default.
        #[arg(required_unless_present = "resume")]
        scene: Option<PathBuf>,
        /// Output directory (default: the scene's [output] dir, or <scene>_out).
        #[arg(long, conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Continue the run in this output directory from its newest checkpoint; the
        /// outputs then equal those of a run never stopped.
        #[arg(long, value_name = "OUT_DIR")]
        resume: Option<PathBuf>,
        /// Also write a checkpoint every this many minutes of wall-clock time.
        #[arg(long, value_name = "MINUTES", value_parser = positive_minutes)]
        checkpoint_every: Option<std::time::Duration>,
        /// Worker threads (default: the scene's, else all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Measure what each setting of a scene costs and buys: the time step, the
    /// regularisation, the skin and the meshes of icosphere and prism shapes swept,
    /// each setting's errors on reference problems built from the scene's shapes and
    /// materials against exact answers, and its cost on a short run of the scene;
    /// writes accuracy.csv, accuracy.json, pareto.png, convergence.png and prints the
    /// cheapest setting that meets the target.
    Accuracy {
        /// The scene (TOML).
        scene: PathBuf,
        /// Wall-clock seconds for the cost runs on the scene.
        #[arg(long, default_value_t = 60.0)]
        budget: f64,
        /// Largest error of the recommendation (0.02 or 2%).
        #[arg(long, default_value = "2%", value_parser = accuracy::fraction)]
        target: f64,
        /// Output directory (default: <scene>_accuracy next to the scene).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads of the cost runs (default: the scene's, else all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
    },
    /// Analyse the packed bed of a finished run (its scene's [bed] section, its
    /// poses.csv): packing.json, porosity profiles, bed.stl.
    Analyze {
        /// The run's output directory.
        dir: PathBuf,
    },
    /// Pack a scene as an FMI 2.0 or 3.0 Co-Simulation FMU.
    Fmu {
        /// The scene (TOML).
        scene: PathBuf,
        /// The FMU to write.
        #[arg(short, long)]
        output: PathBuf,
        /// FMI version: 2 or 3.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
        fmi: u8,
        /// The talus shared library to pack (default: libtalus.so next to this program).
        #[arg(long)]
        library: Option<PathBuf>,
        /// Pack a proxy FMU: its instances forward every call over zenoh to the
        /// `talus serve` node with this key (the library needs the zenoh feature).
        #[arg(long, value_name = "KEY")]
        remote: Option<String>,
        /// With --remote: zenoh endpoint of the node (repeatable), e.g.
        /// tcp/cluster:7447; none: multicast scouting.
        #[arg(long, requires = "remote")]
        connect: Vec<String>,
        /// With --remote: the longest wait for an answer to any call (a step
        /// included), s, before it is an FMI error.
        #[arg(long, requires = "remote", default_value_t = talus::fmi::remote_spec::DEFAULT_TIMEOUT)]
        timeout: f64,
    },
    /// Serve a scene as a zenoh node (feature `zenoh`): queryables KEY/step,
    /// KEY/walls, KEY/info, KEY/state, publisher KEY/forces, liveliness token KEY.
    #[cfg(feature = "zenoh")]
    Serve {
        /// The scene (TOML).
        scene: PathBuf,
        /// Key prefix, e.g. talus/drum.
        #[arg(long)]
        key: String,
        /// Endpoint to listen on (repeatable), e.g. tcp/127.0.0.1:7447.
        #[arg(long)]
        listen: Vec<String>,
        /// Endpoint to connect to (repeatable).
        #[arg(long)]
        connect: Vec<String>,
        /// Enable multicast scouting (off by default).
        #[arg(long)]
        multicast: bool,
        /// Output directory (default: the scene's).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Write the Python classes of the zenoh messages (feature `zenoh`).
    #[cfg(feature = "zenoh")]
    Proto {
        /// Directory for talus/v1/talus_pb2.py.
        #[arg(long)]
        python_out: PathBuf,
    },
    /// Report the shapes of a two-body file and their contact (GJK, overlap volume,
    /// contact point, normal, area), with the time each kernel takes.
    Contact {
        /// A TOML file with two [[body]] entries.
        file: PathBuf,
    },
    /// Measure whole-step throughput (particle-steps/s, contacts/s) on a dense bed of
    /// dodecahedra, a pour of spheres into an STL box, a sphere bed and a lattice of
    /// many distinct shapes, on 1 and 2 threads.
    Bench {
        /// Scale of the particle counts (1: 10 000 dodecahedra and 5000 spheres).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Timed steps per run (scene b is timed over its whole pour).
        #[arg(long, default_value_t = 200)]
        steps: usize,
        /// Measure only these scenes (a, b, c, d; all by default).
        #[arg(long, value_delimiter = ',')]
        scene: Vec<char>,
        /// Measure on these thread counts (with --ranks: the first, per rank).
        #[arg(long, value_delimiter = ',', default_values_t = [1, 2])]
        threads: Vec<usize>,
        /// Under `mpirun -np N` (feature `mpi`): step scene (a) on the N ranks and
        /// print throughput, ghosts, bytes exchanged and time in the exchange.
        #[arg(long)]
        ranks: bool,
        /// The backend that steps the scenes: cpu, or cuda (feature `cuda`, a GPU:
        /// scenes a, b and c, c under Hertz–Mindlin).
        #[arg(long, default_value = "cpu", value_parser = str::parse::<talus::engine::choice::BackendKind>)]
        backend: talus::engine::choice::BackendKind,
        /// Instead of measuring, pour the settled bed of scene (a) and write its
        /// poses to this file (about 20 minutes on two cores).
        #[arg(long, value_name = "FILE")]
        prepare_bed: Option<PathBuf>,
    },
    /// Check a particle mesh (STL or OBJ) and print its mass properties.
    Inspect {
        /// The mesh file.
        mesh: PathBuf,
        /// Use the convex hull of a non-convex or open mesh.
        #[arg(long)]
        hull: bool,
        /// Factor applied to the coordinates (1e-3 for a mesh in mm).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
    },
}

#[cfg(feature = "mpi")]
fn bench_on_ranks(options: &bench::BenchOptions) -> Result<()> {
    bench_ranks::ranks(options)
}

#[cfg(not(feature = "mpi"))]
fn bench_on_ranks(_: &bench::BenchOptions) -> Result<()> {
    anyhow::bail!(
        "--ranks: this talus was built without the `mpi` feature (cargo build --features mpi)"
    )
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Check { scene } => run::check(&scene),
        Command::Run {
            scene,
            out,
            resume,
            checkpoint_every,
            threads,
            quiet,
        } => run::run(
            scene.as_deref(),
            run::RunOptions {
                out,
                threads,
                quiet,
                resume,
                checkpoint_every,
            },
        ),
        Command::Accuracy {
            scene,
            budget,
            target,
            out,
            threads,
        } => accuracy::accuracy(
            &scene,
            accuracy::AccuracyOptions {
                budget: std::time::Duration::from_secs_f64(budget.clamp(0.0, 1e6)),
                target,
                out,
                threads,
            },
        ),
        Command::Contact { file } => contact::contact(&file),
        Command::Analyze { dir } => analyze::analyze(&dir),
        #[cfg(feature = "zenoh")]
        Command::Serve {
            scene,
            key,
            listen,
            connect,
            multicast,
            out,
        } => serve::serve(
            &scene,
            serve::ServeOptions {
                key,
                listen,
                connect,
                multicast,
                out,
            },
        ),
        #[cfg(feature = "zenoh")]
        Command::Proto { python_out } => serve::proto_python(&python_out),
        Command::Fmu {
            scene,
            output,
            fmi,
            library,
            remote,
            connect,
            timeout,
        } => {
            let remote = match remote {
                Some(key) => Some(
                    talus::fmi::remote_spec::RemoteSpec {
                        key,
                        connect,
                        timeout,
                    }
                    .checked()
                    .map_err(|e| anyhow::anyhow!("--remote: {e}"))?,
                ),
                None => None,
            };
            fmu::fmu(&scene, &output, fmi, library, remote)
        }
        Command::Bench {
            prepare_bed: Some(out),
            ..
        } => bench::prepare_bed(&out),
        Command::Bench {
            scale,
            steps,
            scene,
            threads,
            ranks,
            backend,
            ..
        } => {
            let options = bench::BenchOptions {
                scale,
                steps,
                scenes: scene,
                threads,
                backend,
            };
            if ranks && backend != talus::engine::choice::BackendKind::Cpu {
                anyhow::bail!("--ranks: the ranks step on the cpu backend")
            } else if ranks {
                bench_on_ranks(&options)
            } else {
                bench::bench(options)
            }
        }
        Command::Inspect { mesh, hull, scale } => {
            let spec = ShapeSpec::Mesh {
                file: mesh.clone(),
                convex_hull: hull,
                scale,
            };
            let shape = spec.build(Path::new(""))?;
            print_shape(&mesh.display().to_string(), &shape);
            Ok(())
        }
    }
}

/// A positive, finite number of minutes.
fn positive_minutes(text: &str) -> Result<std::time::Duration, String> {
    match text.parse::<f64>() {
        Ok(m) if m.is_finite() && m > 0.0 && m < 1e9 => {
            Ok(std::time::Duration::from_secs_f64(m * 60.0))
        }
        _ => Err(format!("{text} is not a positive number of minutes")),
    }
}

fn print_shape(name: &str, shape: &Shape) {
    println!("{name}:");
    match shape {
        Shape::Sphere(s) => println!("  sphere of radius {:.6e} m", s.radius),
        Shape::Polyhedron(p) => {
            println!(
                "  convex polyhedron: {} vertices, {} edges, {} faces (coplanar triangles merged)",
                p.vertices().len(),
                p.edges().len(),
                p.face_count()
            );
        }
    }
    let i = shape.principal_inertia();
    println!("  volume                  {:.6e} m³", shape.volume());
    println!(
        "  principal inertia / ρ   [{:.6e}, {:.6e}, {:.6e}] m⁵",
        i.x, i.y, i.z
    );
    println!("  circumscribed radius    {:.6e} m", shape.circumradius());
    println!(
        "  volume-equivalent radius {:.6e} m",
        shape.equivalent_radius()
    );
}
