//! `talus fmu`: a scene packed as an FMI 2.0 or 3.0 Co-Simulation FMU.
//!
//! The archive holds `modelDescription.xml` (generated from the variable table of the
//! scene as the FMU will load it), the shared library as
//! `binaries/linux64/talus.so` (FMI 2) or `binaries/x86_64-linux/talus.so` (FMI 3),
//! and under `resources/` the scene as `scene.toml` with every file it names (wall
//! meshes, particle meshes, pose files) at the same relative paths. A proxy FMU
//! (`talus fmu --remote KEY`) holds `resources/remote.toml` besides: its instances
//! forward every call to a `talus serve` node.

use std::path::{Component as PathPart, Path, PathBuf};

use thiserror::Error;

use super::description::{self, FmiVersion};
use super::remote_spec::{REMOTE_FILE, RemoteSpec};
use super::{MODEL_IDENTIFIER, SCENE_FILE, guid};
use crate::cosim::{Component, CosimError};
use crate::geometry::ShapeSpec;
use crate::scene::spec::{ParticleGroupSpec, WallGeometrySpec};
use crate::scene::{Scene, SceneError};

/// Why an FMU could not be written.
#[derive(Debug, Error)]
pub enum PackageError {
    /// The scene is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene does not load as a component from the FMU's resources.
    #[error("the scene does not load from the FMU resources: {0}")]
    Component(#[from] CosimError),
    /// A file the scene names cannot be packed.
    #[error("{field}: {path}: {problem}")]
    Reference {
        /// Field of the scene naming the file.
        field: String,
        /// The path as written.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> PackageError + '_ {
    move |source| PackageError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// What was written.
#[derive(Clone, Debug)]
pub struct FmuSummary {
    /// The guid / instantiation token.
    pub guid: String,
    /// Variables in the description.
    pub variables: usize,
    /// Files packed under `resources/`.
    pub resources: Vec<PathBuf>,
    /// Archive size in bytes.
    pub bytes: usize,
    /// Variables the description leaves out (FMI 2.0 has no arrays: wall meshes and
    /// a large fluid grid's fields), by name.
    pub left_out: Vec<String>,
}

/// Files a scene names, with the field that names each.
fn referenced_files(scene: &Scene) -> Vec<(String, PathBuf)> {
    let spec = &scene.spec;
    let mut files = Vec::new();
    for (name, shape) in &spec.shapes {
        if let ShapeSpec::Mesh { file, .. } = shape {
            files.push((format!("shapes.{name}.file"), file.clone()));
        }
    }
    for (k, wall) in spec.walls.iter().enumerate() {
        if let WallGeometrySpec::Mesh { file, .. } = &wall.geometry {
            files.push((format!("wall[{k}].geometry.file"), file.clone()));
        }
    }
    for (k, group) in spec.particles.iter().enumerate() {
        if let ParticleGroupSpec::File { file, .. } = group {
            files.push((format!("particles[{k}].file"), file.clone()));
        }
    }
    files
}

/// Packs the scene at `scene_path` with the shared library `library` into `out`.
pub fn write_fmu(
    scene_path: &Path,
    library: &Path,
    version: FmiVersion,
    out: &Path,
) -> Result<FmuSummary, PackageError> {
    pack(scene_path, library, version, out, None)
}

/// Packs a proxy FMU: the scene at `scene_path` (for the variables and the guid)
/// and `remote` as `resources/remote.toml`, so that its instances forward every
/// call to the `talus serve` node `remote` names (the library must be built with
/// the `zenoh` feature).
pub fn write_remote_fmu(
    scene_path: &Path,
    library: &Path,
    version: FmiVersion,
    out: &Path,
    remote: &RemoteSpec,
) -> Result<FmuSummary, PackageError> {
    pack(scene_path, library, version, out, Some(remote))
}

fn pack(
    scene_path: &Path,
    library: &Path,
    version: FmiVersion,
    out: &Path,
    remote: Option<&RemoteSpec>,
) -> Result<FmuSummary, PackageError> {
    let scene = Scene::load(scene_path)?;
    let scene_dir = scene_path.parent().unwrap_or(Path::new("."));
    let mut resources = vec![(
        PathBuf::from(SCENE_FILE),
        std::fs::read(scene_path).map_err(io(scene_path))?,
    )];
    for (field, file) in referenced_files(&scene) {
        let inside = file
            .components()
            .all(|c| matches!(c, PathPart::Normal(_) | PathPart::CurDir));
        if !inside {
            return Err(PackageError::Reference {
                field,
                path: file,
                problem: "an FMU packs files at or below the scene's directory; \
                          give a relative path without '..' (move or copy the file)"
                    .into(),
            });
        }
        let source = scene_dir.join(&file);
        let bytes = std::fs::read(&source).map_err(io(&source))?;
        resources.push((file, bytes));
    }

    // The component is loaded without it: a proxy's variables are the scene's.
    let staged = resources.len();
    if let Some(remote) = remote {
        resources.push((PathBuf::from(REMOTE_FILE), remote.to_toml().into_bytes()));
    }
    // Load the component exactly as the FMU will: from a resources directory.
    let staging = std::env::temp_dir().join(format!(
        "talus-fmu-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    let result = (|| {
        for (path, bytes) in &resources[..staged] {
            let target = staging.join(path);
            if let Some(dir) = target.parent() {
                std::fs::create_dir_all(dir).map_err(io(dir))?;
            }
            std::fs::write(&target, bytes).map_err(io(&target))?;
        }
        Ok::<_, PackageError>(Component::instantiate(&staging, SCENE_FILE)?)
    })();
    let _ = std::fs::remove_dir_all(&staging);
    let component = result?;

    let model = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let (xml, platform) = match version {
        FmiVersion::Two => (description::fmi2(&component, &model), "linux64"),
        FmiVersion::Three => (description::fmi3(&component, &model), "x86_64-linux"),
    };
    let library_bytes = std::fs::read(library).map_err(io(library))?;
    let mut entries = vec![
        ("modelDescription.xml".to_string(), xml.into_bytes()),
        (
            format!("binaries/{platform}/{MODEL_IDENTIFIER}.so"),
            library_bytes,
        ),
    ];
    for (path, bytes) in &resources {
        let name = path
            .components()
            .filter_map(|c| match c {
                PathPart::Normal(s) => Some(s.to_string_lossy().into_owned()),
                _ => None,
            })
            .collect::<Vec<_>>()
            .join("/");
        entries.push((format!("resources/{name}"), bytes.clone()));
    }
    let archive = zip_archive(&entries).map_err(io(out))?;
    std::fs::write(out, &archive).map_err(io(out))?;
    Ok(FmuSummary {
        guid: guid(component.fingerprint()),
        variables: component.variables().len(),
        resources: resources.into_iter().map(|r| r.0).collect(),
        bytes: archive.len(),
        left_out: match version {
            FmiVersion::Two => component
                .variables()
                .iter()
                .filter(|v| v.array_only)
                .map(|v| v.name.clone())
                .collect(),
            FmiVersion::Three => Vec::new(),
        },
    })
}

/// `entries` (path inside the archive, contents) as a zip archive, every entry
/// deflated; the shared library executable, the rest read-only for others. Entries
/// carry the zip epoch (1980-01-01) as their time, so the same scene and library give
/// the same bytes.
fn zip_archive(entries: &[(String, Vec<u8>)]) -> std::io::Result<Vec<u8>> {
    use std::io::Write;
    use zip::write::SimpleFileOptions;

    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, data) in entries {
        let mode = if name.ends_with(".so") { 0o755 } else { 0o644 };
        let options = SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .last_modified_time(zip::DateTime::default())
            .unix_permissions(mode)
            // Libraries past 4 GiB are not expected, but zip64 costs nothing when
            // not needed.
            .large_file(data.len() as u64 >= u32::MAX as u64);
        zip.start_file(name.as_str(), options)
            .map_err(std::io::Error::other)?;
        zip.write_all(data)?;
    }
    Ok(zip.finish().map_err(std::io::Error::other)?.into_inner())
}
