//! `talus fmu` packing: the archive's entries, the files a scene names, and paths
//! that cannot be packed.

use std::path::Path;

use talus::fmi::description::FmiVersion;
use talus::fmi::package::{PackageError, write_fmu};

/// One entry of an archive as the `zip` crate's reader gives it back (which checks
/// its CRC-32).
struct Entry {
    name: String,
    data: Vec<u8>,
    method: zip::CompressionMethod,
    packed: u64,
    mode: Option<u32>,
}

fn entries(archive: &[u8]) -> Vec<Entry> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(archive)).unwrap();
    (0..zip.len())
        .map(|k| {
            let mut file = zip.by_index(k).unwrap();
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut file, &mut data).unwrap();
            Entry {
                name: file.name().to_string(),
                data,
                method: file.compression(),
                packed: file.compressed_size(),
                mode: file.unix_mode(),
            }
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
        let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        for name in [
            "modelDescription.xml",
            &format!("binaries/{platform}/talus.so"),
            "resources/scene.toml",
            "resources/floor.stl",
        ] {
            assert!(names.contains(&name), "{name} missing from {names:?}");
        }
        for e in &entries {
            assert_eq!(e.method, zip::CompressionMethod::Deflated, "{}", e.name);
            let executable = e.name.ends_with(".so");
            let mode = if executable { 0o755 } else { 0o644 };
            assert_eq!(e.mode.map(|m| m & 0o777), Some(mode), "{}", e.name);
            if executable {
                assert_eq!(e.data, fake, "the library comes back as packed");
                // Deflated: the repetitive 88 kB library packs to a small fraction.
                assert!(e.packed < e.data.len() as u64 / 10, "{} bytes", e.packed);
            }
        }
        let scene = &entries
            .iter()
            .find(|e| e.name == "resources/scene.toml")
            .unwrap()
            .data;
        assert_eq!(
            scene,
            &std::fs::read(root().join("examples/sliding_cuboid/scene.toml")).unwrap()
        );
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
