//! `talus fmu` packing: the archive's entries, the files a scene names, and paths
//! that cannot be packed.

use std::path::Path;

use talus::fmi::description::FmiVersion;
use talus::fmi::package::{PackageError, write_fmu};

/// Entry names from a zip's central directory.
fn entries(zip: &[u8]) -> Vec<String> {
    let end = zip.len() - 22;
    assert_eq!(&zip[end..end + 4], &0x0605_4b50u32.to_le_bytes());
    let count = u16::from_le_bytes([zip[end + 10], zip[end + 11]]) as usize;
    let mut at = u32::from_le_bytes(zip[end + 16..end + 20].try_into().unwrap()) as usize;
    let mut names = Vec::new();
    for _ in 0..count {
        assert_eq!(&zip[at..at + 4], &0x0201_4b50u32.to_le_bytes());
        let len = u16::from_le_bytes([zip[at + 28], zip[at + 29]]) as usize;
        names.push(String::from_utf8(zip[at + 46..at + 46 + len].to_vec()).unwrap());
        at += 46 + len;
    }
    names
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_scene_with_a_wall_mesh_packs_its_mesh_and_the_library() {
    let dir = std::env::temp_dir().join(format!("talus-fmu-pack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let library = dir.join("libfake.so");
    std::fs::write(&library, b"not really a library").unwrap();
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
        let names = entries(&std::fs::read(&out).unwrap());
        assert!(
            names.contains(&"modelDescription.xml".to_string()),
            "{names:?}"
        );
        assert!(
            names.contains(&format!("binaries/{platform}/talus.so")),
            "{names:?}"
        );
        assert!(
            names.contains(&"resources/scene.toml".to_string()),
            "{names:?}"
        );
        assert!(
            names.contains(&"resources/floor.stl".to_string()),
            "{names:?}"
        );
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
