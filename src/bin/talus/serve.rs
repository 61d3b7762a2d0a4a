//! `talus serve`: a scene as a zenoh node; `talus proto`: the Python message classes.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use talus::cosim::{Component, VarRef};
use talus::transport::{Node, NodeConfig, Service};

/// Options of `talus serve`.
pub struct ServeOptions {
    pub key: String,
    pub listen: Vec<String>,
    pub connect: Vec<String>,
    pub multicast: bool,
    pub out: Option<PathBuf>,
}

pub fn serve(scene: &Path, options: ServeOptions) -> Result<()> {
    let dir = scene.parent().unwrap_or(Path::new(""));
    let file = scene.file_name().context("the scene path names no file")?;
    let mut component = Component::instantiate(dir, &file.to_string_lossy())
        .with_context(|| format!("cannot load {}", scene.display()))?;
    let out = options
        .out
        .unwrap_or_else(|| component.scene().output_dir());
    let var = component.variable("output_dir")?;
    component.set_string(&[VarRef { var, element: 0 }], &[&out.to_string_lossy()])?;
    component.enter_initialization_mode(0.0)?;
    component.exit_initialization_mode()?;

    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("cannot install the SIGINT/SIGTERM handler")?;
    let config = NodeConfig {
        key: options.key.clone(),
        listen: options.listen,
        connect: options.connect,
        multicast: options.multicast,
    };
    let node = Node::start(Service::new(component), &config)?;
    println!(
        "serving {} as '{}' (queryables {k}/step, {k}/walls, {k}/info, {k}/state; publisher {k}/forces); Ctrl-C or SIGTERM stops",
        scene.display(),
        options.key,
        k = options.key
    );
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let mut service = node.stop();
    let component = service.component_mut();
    let time = component.simulation().map_or(0.0, |s| s.world().time);
    component.terminate()?;
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
