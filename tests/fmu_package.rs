//! `talus fmu` packing: the archive's entries, the files a scene names, and paths
//! that cannot be packed.

use std::path::Path;

use talus::fmi::description::FmiVersion;
use talus::fmi::package::{PackageError, write_fmu};

/// The archive's entries, each read back through the `zip` crate's reader (which
/// checks every entry's CRC-32): name, contents, compression and Unix mode.
fn entries(archive: &[u8]) -> Vec<(String, Vec<u8>, zip::CompressionMethod, Option<u32>)> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(archive)).unwrap();
    (0..zip.len())
        .map(|k| {
            let mut file = zip.by_index(k).unwrap();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut file, &mut data).unwrap();
            (
                file.name().to_string(),
                data,
                file.compression(),
                file.unix_mode(),
            )
        })
        .collect()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_scene_with_a_wall_mesh_packs_its_mesh_and_the_library() {
    let dir = std::env::temp_dir().join(format!("talus-fmu-pack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let library = dir.join("libfake.so");
    // Compressible, like a real library.
    let fake: Vec<u8> = b"not really a library. ".repeat(4000);
    std::fs::write(&library, &fake).unwrap();
    for (version, platform) in [
        (FmiVersion::Two, "linux64"),
        (FmiVersion::Three, "x86_64-linux"),
    ] {
        let out = dir.join("cuboid.fmu");
        let summary = write_fmu(
            &root().join("examples/sliding_cuboid/scene.toml"),
            &library,
            version,
            &out,
        )
        .unwrap();
        let archive = std::fs::read(&out).unwrap();
        let entries = entries(&archive);
        let names: Vec<&str> = entries.iter().map(|e| e.0.as_str()).collect();
        for name in [
            "modelDescription.xml",
            &format!("binaries/{platform}/talus.so"),
            "resources/scene.toml",
            "resources/floor.stl",
        ] {
            assert!(names.contains(&name), "{name} missing from {names:?}");
        }
        for (name, data, method, mode) in &entries {
            assert_eq!(*method, zip::CompressionMethod::Deflated, "{name}");
            let executable = name.ends_with(".so");
            assert_eq!(
                mode.map(|m| m & 0o777),
                Some(if executable { 0o755 } else { 0o644 })
            );
            if executable {
                assert_eq!(data, &fake, "the library comes back as packed");
            }
        }
        let scene = &entries
            .iter()
            .find(|e| e.0 == "resources/scene.toml")
            .unwrap()
            .1;
        assert_eq!(
            scene,
            &std::fs::read(root().join("examples/sliding_cuboid/scene.toml")).unwrap()
        );
        // Deflated: the 88 kB library packs to a small fraction of itself.
        assert!(archive.len() < fake.len() / 10, "{} bytes", archive.len());
        assert_eq!(summary.bytes, archive.len());
        // Packed again: the same bytes (no clock in the archive).
        let again = dir.join("again.fmu");
        write_fmu(
            &root().join("examples/sliding_cuboid/scene.toml"),
            &library,
            version,
            &again,
        )
        .unwrap();
        assert!(std::fs::read(&again).unwrap() == archive);
        assert_eq!(summary.resources.len(), 2);
        assert!(summary.guid.starts_with('{') && summary.guid.len() == 38);
    }
}

#[test]
fn a_file_outside_the_scene_directory_is_refused_by_field() {
    let dir = std::env::temp_dir().join(format!("talus-fmu-outside-{}", std::process::id()));
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    std::fs::copy(
        root().join("examples/sliding_cuboid/floor.stl"),
        dir.join("floor.stl"),
    )
    .unwrap();
    let text = std::fs::read_to_string(root().join("examples/sliding_cuboid/scene.toml"))
        .unwrap()
        .replace("\"floor.stl\"", "\"../floor.stl\"");
    std::fs::write(scenes.join("scene.toml"), text).unwrap();
    let err = write_fmu(
        &scenes.join("scene.toml"),
        &dir.join("none.so"),
        FmiVersion::Two,
        &dir.join("x.fmu"),
    )
    .unwrap_err();
    assert!(matches!(err, PackageError::Reference { .. }), "{err}");
    assert!(err.to_string().contains("wall[0].geometry.file"), "{err}");
}
