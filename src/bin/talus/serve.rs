//! `talus serve`: a scene as a zenoh node, in one process or on the ranks of
//! `mpirun -np N talus serve` (rank 0 the node, every rank stepping its share);
//! `talus proto`: the Python message classes.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use talus::cosim::{Component, VarRef};
use talus::transport::{Node, NodeConfig, Service};

use crate::launch::Launch;

/// Options of `talus serve`.
pub struct ServeOptions {
    pub key: String,
    pub listen: Vec<String>,
    pub connect: Vec<String>,
    pub multicast: bool,
    pub out: Option<PathBuf>,
}

pub fn serve(scene: &Path, options: ServeOptions) -> Result<()> {
    let mut launch = Launch::detect()?;
    let result = serve_in(&mut launch, scene, options);
    result.map_err(|e| launch.fail(e))
}

fn serve_in(launch: &mut Launch, scene: &Path, options: ServeOptions) -> Result<()> {
    // Every rank stops on rank 0's word, not on its own signal (mpirun hands a
    // SIGTERM to all of them).
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("cannot install the SIGINT/SIGTERM handler")?;
    let ranks = launch.take_ranks()?;
    let dir = scene.parent().unwrap_or(Path::new(""));
    let file = scene.file_name().context("the scene path names no file")?;
    let file = file.to_string_lossy();
    let mut component = match &ranks {
        None => Component::instantiate(dir, &file),
        Some(r) => Component::instantiate_on_ranks(dir, &file, r.another()),
    }
    .with_context(|| format!("cannot load {}", scene.display()))?;
    let out = options
        .out
        .unwrap_or_else(|| component.scene().output_dir());
    let var = component.variable("output_dir")?;
    component.set_string(&[VarRef { var, element: 0 }], &[&out.to_string_lossy()])?;
    if component.scene().spec.simulation.threads == 0 && ranks.is_some() {
        // The ranks on this machine share its cores.
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = (cores / launch.local_ranks()).max(1) as i64;
        let var = component.variable("threads")?;
        component.set_integer(&[VarRef { var, element: 0 }], &[threads])?;
    }
    // A proxy FMU's master resets the component when it attaches: it keeps these.
    component.keep_parameters_on_reset()?;
    component.enter_initialization_mode(0.0)?;
    component.exit_initialization_mode()?;
    let service = match ranks {
        None => Service::new(component),
        Some(r) if r.rank() != 0 => {
            Service::on_ranks(component, r).follow()?;
            return Ok(());
        }
        Some(r) => Service::on_ranks(component, r),
    };

    let config = NodeConfig {
        key: options.key.clone(),
        listen: options.listen,
        connect: options.connect,
        multicast: options.multicast,
    };
    let node = Node::start(service, &config)?;
    println!(
        "serving {} as '{}'{} (queryables {k}/step, {k}/walls, {k}/info, {k}/state; publisher {k}/forces); Ctrl-C or SIGTERM stops",
        scene.display(),
        options.key,
        launch
            .rank_count()
            .map_or(String::new(), |n| format!(" on {n} MPI ranks")),
        k = options.key
    );
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let component = node.stop().finish()?;
    let time = component.simulation().map_or(0.0, |s| s.world().time);
    println!("stopped at t = {time} s; outputs in {}", out.display());
    Ok(())
}
/// Writes the Python classes of the messages (`talus/v1/talus_pb2.py`) under `out`.
pub fn proto_python(out: &Path) -> Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("proto");
    std::fs::create_dir_all(out)?;
    let status = std::process::Command::new(env!("TALUS_PROTOC"))
        .arg(format!("--proto_path={}", root.display()))
        .arg(format!("--python_out={}", out.display()))
        .arg(root.join("talus/v1/talus.proto"))
        .status()
        .context("cannot run protoc")?;
    if !status.success() {
        bail!("protoc failed");
    }
    println!("wrote {}", out.join("talus/v1/talus_pb2.py").display());
    Ok(())
}
