//! FMI 2.0 and 3.0 Co-Simulation over the [`Component`], and FMU packaging.
//!
//! The cdylib exports every function of both standards (a master resolves them all
//! when it loads the library). Supported: the co-simulation life cycle, reals,
//! integers and strings (FMI 3: Float64, Int32, String, with array variables), and
//! the FMU state (get, set, free, serialise). Everything else answers the error
//! status with a logged message and changes nothing.
//!
//! One FMU is one scene: `talus fmu` writes the scene to `resources/scene.toml`
//! (with the files it refers to), the variable table to `modelDescription.xml`, and
//! the guid (FMI 3: instantiation token) is made from the scene's
//! [fingerprint](crate::cosim::fingerprint), so instantiation refuses a
//! description that does not match the scene it finds.
//!
//! Each instance owns its worker threads (see [`crate::cosim::pool`]); after
//! `FreeInstance` returns, no thread of the library runs, so a master may `dlclose`
//! it and load it again. A proxy FMU's instances (`resources/remote.toml`, see
//! [`remote_spec`]) forward every call to a `talus serve` node over zenoh; zenoh
//! keeps its runtime's threads for the life of the process, whose thread-local
//! destructors keep glibc from unloading the library at `dlclose` (fmpy frees the
//! library after each simulation; the tests simulate proxies and local FMUs in turn
//! in one process).

pub mod description;
mod fmi2;
mod fmi3;
pub mod package;
#[cfg(feature = "zenoh")]
mod remote;
pub mod remote_spec;
mod slave;
mod state;

use std::ffi::{CString, c_char, c_int, c_void};
use std::path::PathBuf;

use crate::cosim::{Component, VarRef, Variable};
use crate::ffi::guard::catch;
use slave::Slave;

/// Name of the shared library inside an FMU (`binaries/<platform>/talus.so`).
pub const MODEL_IDENTIFIER: &str = "talus";
/// Where the scene lives inside an FMU's resources.
pub const SCENE_FILE: &str = "scene.toml";

/// Status codes (the same numbers in FMI 2 and 3).
pub(crate) const OK: c_int = 0;
pub(crate) const WARNING: c_int = 1;
pub(crate) const ERROR: c_int = 3;

/// The guid (FMI 2) or instantiation token (FMI 3) of a scene's FMU.
pub fn guid(fingerprint: u64) -> String {
    let second = fingerprint.rotate_left(29) ^ 0x9e37_79b9_7f4a_7c15;
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        fingerprint >> 32,
        (fingerprint >> 16) & 0xffff,
        fingerprint & 0xffff,
        second >> 48,
        second & 0xffff_ffff_ffff
    )
}

/// The FMI 2 scalar variables: every element of every variable except the arrays
/// whose size depends on a mesh; the value reference is the position in this list.
/// Vectors are named `name[1]`, `name[2]` ... (structured naming).
pub fn fmi2_scalars(variables: &[Variable]) -> Vec<(VarRef, String)> {
    let mut out = Vec::new();
    for (var, v) in variables.iter().enumerate() {
        if v.array_only {
            continue;
        }
        for element in 0..v.size {
            let name = if v.size == 1 {
                v.name.clone()
            } else {
                format!("{}[{}]", v.name, element + 1)
            };
            out.push((VarRef { var, element }, name));
        }
    }
    out
}

/// A local directory from an FMI 2 resource URI (`file:///a/b`, `file:/a/b`,
/// percent-encoded) or an FMI 3 resource path.
pub fn resource_dir(location: &str) -> PathBuf {
    let path = location
        .strip_prefix("file://localhost")
        .or_else(|| location.strip_prefix("file://"))
        .or_else(|| location.strip_prefix("file:"))
        .unwrap_or(location);
    let bytes = path.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                decoded.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        decoded.push(bytes[i]);
        i += 1;
    }
    PathBuf::from(String::from_utf8_lossy(&decoded).into_owned())
}

/// The FMI 2 logger (variadic in C; talus passes a message with `%` doubled).
pub(crate) type Fmi2Logger = unsafe extern "C" fn(
    env: *mut c_void,
    instance: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
    ...
);

/// The FMI 3 log-message callback.
pub(crate) type Fmi3Logger = unsafe extern "C" fn(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
);

/// Where an instance's messages go.
#[derive(Clone, Copy)]
pub(crate) enum LogSink {
    Fmi2(Option<Fmi2Logger>, *mut c_void),
    Fmi3(Option<Fmi3Logger>, *mut c_void),
}

/// One FMU instance.
pub(crate) struct Instance {
    pub name: CString,
    pub component: Box<dyn Slave>,
    pub sink: LogSink,
    pub logging_on: bool,
    /// Strings handed out by GetString, alive until the next call that returns some.
    pub strings: Vec<CString>,
    /// FMI 2: the start time from SetupExperiment.
    pub start_time: f64,
    /// FMI 2: value reference → element.
    pub scalars: Vec<VarRef>,
}

fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// Sends a message to a logger (no instance yet, or through one).
pub(crate) fn log_to(sink: LogSink, instance: &str, status: c_int, category: &str, message: &str) {
    let name = c_string(instance);
    let category = c_string(category);
    match sink {
        LogSink::Fmi2(Some(logger), env) => {
            let message = c_string(&message.replace('%', "%%"));
            // SAFETY: the master gave this logger for this purpose.
            unsafe {
                logger(
                    env,
                    name.as_ptr(),
                    status,
                    category.as_ptr(),
                    message.as_ptr(),
                )
            };
        }
        LogSink::Fmi3(Some(logger), env) => {
            let message = c_string(&format!("{instance}: {message}"));
            // SAFETY: as above.
            unsafe { logger(env, status, category.as_ptr(), message.as_ptr()) };
        }
        _ => {}
    }
}

impl Instance {
    /// Loads the scene from the resources and checks the guid.
    pub fn create(
        name: &str,
        guid_given: &str,
        resources: PathBuf,
        sink: LogSink,
        logging_on: bool,
    ) -> Result<Instance, String> {
        if !resources.join(SCENE_FILE).is_file() {
            return Err(format!(
                "the resources ({}) hold no {SCENE_FILE}",
                resources.display()
            ));
        }
        let component: Box<dyn Slave> = if resources.join(remote_spec::REMOTE_FILE).is_file() {
            remote_slave(&resources)?
        } else {
            Box::new(Component::instantiate(&resources, SCENE_FILE).map_err(|e| e.to_string())?)
        };
        let expected = guid(component.fingerprint());
        if guid_given != expected {
            return Err(format!(
                "the guid {guid_given} does not match the scene in the resources ({expected}): \
                 the modelDescription.xml belongs to another scene or talus version"
            ));
        }
        let scalars = fmi2_scalars(component.variables())
            .into_iter()
            .map(|s| s.0)
            .collect();
        Ok(Instance {
            name: c_string(name),
            component,
            sink,
            logging_on,
            strings: Vec::new(),
            start_time: 0.0,
            scalars,
        })
    }

    /// Logs a message through the master's logger.
    pub fn log(&self, status: c_int, category: &str, message: &str) {
        if status == OK && !self.logging_on {
            return;
        }
        log_to(
            self.sink,
            &self.name.to_string_lossy(),
            status,
            category,
            message,
        );
    }

    /// Logs the component's warnings (as `talus check` gives them) as warnings.
    pub fn log_warnings(&self) {
        for w in self.component.warnings() {
            self.log(WARNING, "logStatusWarning", &w);
        }
    }

    /// Keeps strings alive for the master and returns their pointers.
    pub fn hand_out(&mut self, strings: Vec<String>) -> Vec<*const c_char> {
        self.strings = strings.iter().map(|s| c_string(s)).collect();
        self.strings.iter().map(|s| s.as_ptr()).collect()
    }
}

/// The instance of a proxy FMU (see [`remote_spec`]).
#[cfg(feature = "zenoh")]
fn remote_slave(resources: &std::path::Path) -> Result<Box<dyn Slave>, String> {
    Ok(Box::new(remote::Remote::connect(resources)?))
}

#[cfg(not(feature = "zenoh"))]
fn remote_slave(_: &std::path::Path) -> Result<Box<dyn Slave>, String> {
    Err(format!(
        "this FMU forwards its calls to a talus node ({}), but its library was built \
         without the `zenoh` feature",
        remote_spec::REMOTE_FILE
    ))
}

/// Runs an entry point on an instance: null checked, panics caught (the component
/// then goes to the error state), errors logged as `call: message`.
pub(crate) fn on_instance(
    ptr: *mut c_void,
    call: &str,
    f: impl FnOnce(&mut Instance) -> Result<c_int, String>,
) -> c_int {
    if ptr.is_null() {
        return ERROR;
    }
    // SAFETY: a non-null instance pointer comes from Instantiate and is not yet freed.
    let inst = unsafe { &mut *(ptr as *mut Instance) };
    match catch(|| f(inst)) {
        Ok(status) => status,
        Err(message) => {
            if message.starts_with("internal error") {
                inst.component.fail();
            }
            inst.log(ERROR, "logStatusError", &format!("{call}: {message}"));
            ERROR
        }
    }
}

/// Answers a function talus does not support.
pub(crate) fn unsupported(ptr: *mut c_void, call: &str) -> c_int {
    on_instance(ptr, call, |_| {
        Err("not supported by talus (a co-simulation FMU without event mode)".into())
    })
}

/// Frees an instance (null is ignored).
pub(crate) fn free_instance(ptr: *mut c_void) {
    if !ptr.is_null() {
        let _ = catch(|| {
            // SAFETY: the pointer came from Box::into_raw in Instantiate.
            drop(unsafe { Box::from_raw(ptr as *mut Instance) });
            Ok(())
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cosim::Mode;

    #[test]
    fn a_panic_in_an_entry_point_is_logged_and_leaves_the_error_state() {
        let dir = std::env::temp_dir().join(format!("talus-fmi-panic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/drum_fmu/drum.toml");
        std::fs::copy(scene, dir.join(SCENE_FILE)).unwrap();
        let component = Component::instantiate(&dir, SCENE_FILE).unwrap();
        let token = guid(component.fingerprint());
        let inst = Instance::create(
            "x",
            &token,
            dir.clone(),
            LogSink::Fmi3(None, std::ptr::null_mut()),
            true,
        )
        .unwrap();
        assert!(
            Instance::create(
                "x",
                "{wrong}",
                dir,
                LogSink::Fmi3(None, std::ptr::null_mut()),
                true
            )
            .is_err()
        );
        let ptr = Box::into_raw(Box::new(inst)) as *mut c_void;
        assert_eq!(on_instance(ptr, "test", |_| panic!("deliberate")), ERROR);
        let inst = unsafe { &*(ptr as *mut Instance) };
        assert_eq!(inst.component.mode(), Mode::Error);
        assert_eq!(unsupported(ptr, "fmi3EnterEventMode"), ERROR);
        free_instance(ptr);
        assert_eq!(on_instance(std::ptr::null_mut(), "test", |_| Ok(OK)), ERROR);
    }

    #[test]
    fn resource_uris_become_paths() {
        assert_eq!(
            resource_dir("file:///tmp/a%20b/resources"),
            PathBuf::from("/tmp/a b/resources")
        );
        assert_eq!(resource_dir("file:/tmp/x"), PathBuf::from("/tmp/x"));
        assert_eq!(
            resource_dir("file://localhost/tmp/x/"),
            PathBuf::from("/tmp/x/")
        );
        assert_eq!(resource_dir("/tmp/x/"), PathBuf::from("/tmp/x/"));
        assert_eq!(resource_dir("/tmp/100%"), PathBuf::from("/tmp/100%"));
    }

    #[test]
    fn guids_have_the_uuid_form_and_differ_by_scene() {
        let g = guid(0x0123_4567_89ab_cdef);
        assert_eq!(g.len(), 38);
        assert!(g.starts_with("{01234567-89ab-cdef-"));
        assert_ne!(guid(1), guid(2));
    }
}
