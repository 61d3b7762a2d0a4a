//! The FMI 2.0 Co-Simulation entry points (all 34 functions of the standard's
//! header; see the [module docs](super)).

use std::ffi::{c_char, c_int, c_uint, c_void};

use super::state::{deserialise, free_state, get_state, serialise, serialised_size, set_state};
use super::{
    ERROR, Fmi2Logger, Instance, LogSink, OK, free_instance, log_to, on_instance, resource_dir,
    unsupported,
};
use crate::cosim::{Mode, VarRef};
use crate::ffi::guard::{catch, put, slice, slice_mut, text};

type Component = *mut c_void;
type Status = c_int;
type ValueReference = c_uint;
type Boolean = c_int;

const CO_SIMULATION: c_int = 1;
const LAST_SUCCESSFUL_TIME: c_int = 2;
const TERMINATED: c_int = 3;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Fmi2Logger>,
    allocate_memory: *const c_void,
    free_memory: *const c_void,
    step_finished: *const c_void,
    component_environment: *mut c_void,
}

fn refs(inst: &Instance, vr: &[ValueReference]) -> Result<Vec<VarRef>, String> {
    vr.iter()
        .map(|&v| {
            inst.scalars
                .get(v as usize)
                .copied()
                .ok_or_else(|| format!("unknown value reference {v}"))
        })
        .collect()
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    logging_on: Boolean,
    _n: usize,
    _categories: *const *const c_char,
) -> Status {
    on_instance(c, "fmi2SetDebugLogging", |inst| {
        inst.logging_on = logging_on != 0;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: Boolean,
    logging_on: Boolean,
) -> Component {
    let sink = if functions.is_null() {
        LogSink::Fmi2(None, std::ptr::null_mut())
    } else {
        // SAFETY: the master passes a valid callback structure.
        let f = unsafe { &*functions };
        LogSink::Fmi2(f.logger, f.component_environment)
    };
    let name = unsafe { text(instance_name, "instanceName") }
        .unwrap_or("talus")
        .to_string();
    let created = catch(|| {
        if fmu_type != CO_SIMULATION {
            return Err("talus is a co-simulation FMU; model exchange is not offered".into());
        }
        let guid = unsafe { text(guid, "fmuGUID") }?;
        let location = unsafe { text(resource_location, "fmuResourceLocation") }?;
        Instance::create(&name, guid, resource_dir(location), sink, logging_on != 0)
    });
    match created {
        Ok(inst) => Box::into_raw(Box::new(inst)) as Component,
        Err(message) => {
            log_to(
                sink,
                &name,
                ERROR,
                "logStatusError",
                &format!("fmi2Instantiate: {message}"),
            );
            std::ptr::null_mut()
        }
    }
}

/// # Safety
/// `c` comes from fmi2Instantiate and is not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    free_instance(c);
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Component,
    _tolerance_defined: Boolean,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: Boolean,
    _stop_time: f64,
) -> Status {
    on_instance(c, "fmi2SetupExperiment", |inst| {
        if inst.component.mode() != Mode::Instantiated {
            return Err(format!("not allowed in {} mode", inst.component.mode()));
        }
        if !start_time.is_finite() {
            return Err(format!("start time {start_time} is not finite"));
        }
        inst.start_time = start_time;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> Status {
    on_instance(c, "fmi2EnterInitializationMode", |inst| {
        let t = inst.start_time;
        inst.component
            .enter_initialization_mode(t)
            .map_err(|e| e.to_string())?;
        inst.log_warnings();
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Component) -> Status {
    on_instance(c, "fmi2ExitInitializationMode", |inst| {
        inst.component
            .exit_initialization_mode()
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: Component) -> Status {
    on_instance(c, "fmi2Terminate", |inst| {
        inst.component.terminate().map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: Component) -> Status {
    on_instance(c, "fmi2Reset", |inst| {
        inst.component.reset()?;
        inst.start_time = 0.0;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *mut f64,
) -> Status {
    on_instance(c, "fmi2GetReal", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        inst.component
            .get_real(&refs, out)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *mut c_int,
) -> Status {
    on_instance(c, "fmi2GetInteger", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let mut wide = vec![0i64; nvr];
        inst.component
            .get_integer(&refs, &mut wide)
            .map_err(|e| e.to_string())?;
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        for (o, w) in out.iter_mut().zip(wide) {
            *o = w.clamp(c_int::MIN as i64, c_int::MAX as i64) as c_int;
        }
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    _value: *mut Boolean,
) -> Status {
    on_instance(c, "fmi2GetBoolean", |inst| no_booleans(inst, vr, nvr))
}

fn no_booleans(inst: &Instance, vr: *const ValueReference, nvr: usize) -> Result<Status, String> {
    let vr = unsafe { slice(vr, nvr, "vr") }?;
    let refs = refs(inst, vr)?;
    match refs.first() {
        None => Ok(OK),
        Some(r) => Err(format!(
            "'{}' is not a Boolean (talus has no Boolean variables)",
            inst.component.variables()[r.var].name
        )),
    }
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *mut *const c_char,
) -> Status {
    on_instance(c, "fmi2GetString", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let strings = inst
            .component
            .get_string(&refs)
            .map_err(|e| e.to_string())?;
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        out.copy_from_slice(&inst.hand_out(strings));
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *const f64,
) -> Status {
    on_instance(c, "fmi2SetReal", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let values = unsafe { slice(value, nvr, "value") }?;
        inst.component
            .set_real(&refs, values)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *const c_int,
) -> Status {
    on_instance(c, "fmi2SetInteger", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let values: Vec<i64> = unsafe { slice(value, nvr, "value") }?
            .iter()
            .map(|&x| x as i64)
            .collect();
        inst.component
            .set_integer(&refs, &values)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    _value: *const Boolean,
) -> Status {
    on_instance(c, "fmi2SetBoolean", |inst| no_booleans(inst, vr, nvr))
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: Component,
    vr: *const ValueReference,
    nvr: usize,
    value: *const *const c_char,
) -> Status {
    on_instance(c, "fmi2SetString", |inst| {
        let refs = refs(inst, unsafe { slice(vr, nvr, "vr") }?)?;
        let pointers = unsafe { slice(value, nvr, "value") }?;
        let values = pointers
            .iter()
            .map(|&p| unsafe { text(p, "value") })
            .collect::<Result<Vec<&str>, String>>()?;
        inst.component
            .set_string(&refs, &values)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: Component, state: *mut *mut c_void) -> Status {
    on_instance(c, "fmi2GetFMUstate", |inst| get_state(inst, state))
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: Component, state: *mut c_void) -> Status {
    on_instance(c, "fmi2SetFMUstate", |inst| set_state(inst, state))
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: Component, state: *mut *mut c_void) -> Status {
    on_instance(c, "fmi2FreeFMUstate", |_| free_state(state))
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: Component,
    state: *mut c_void,
    size: *mut usize,
) -> Status {
    on_instance(c, "fmi2SerializedFMUstateSize", |inst| {
        serialised_size(inst, state, size)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: Component,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Status {
    on_instance(c, "fmi2SerializeFMUstate", |inst| {
        serialise(inst, state, bytes, size)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    on_instance(c, "fmi2DeSerializeFMUstate", |inst| {
        deserialise(inst, bytes, size, state)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    _unknown: *const ValueReference,
    _n_unknown: usize,
    _known: *const ValueReference,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Status {
    unsupported(c, "fmi2GetDirectionalDerivative")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _nvr: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Status {
    unsupported(c, "fmi2SetRealInputDerivatives")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _nvr: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Status {
    unsupported(c, "fmi2GetRealOutputDerivatives")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: Component,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_prior: Boolean,
) -> Status {
    on_instance(c, "fmi2DoStep", |inst| {
        inst.component
            .do_step(current_communication_point, communication_step_size)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: Component) -> Status {
    unsupported(c, "fmi2CancelStep")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, _kind: c_int, _value: *mut c_int) -> Status {
    unsupported(c, "fmi2GetStatus")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> Status {
    on_instance(c, "fmi2GetRealStatus", |inst| {
        if kind != LAST_SUCCESSFUL_TIME {
            return Err(format!("status kind {kind} is not a real status"));
        }
        let t = inst.component.time().unwrap_or(inst.start_time);
        unsafe { put(value, t, "value") }?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: Component,
    _kind: c_int,
    _value: *mut c_int,
) -> Status {
    unsupported(c, "fmi2GetIntegerStatus")
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: Component,
    kind: c_int,
    value: *mut Boolean,
) -> Status {
    on_instance(c, "fmi2GetBooleanStatus", |_| {
        if kind != TERMINATED {
            return Err(format!("status kind {kind} is not a Boolean status"));
        }
        unsafe { put(value, 0, "value") }?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 2.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: Component,
    _kind: c_int,
    _value: *mut *const c_char,
) -> Status {
    unsupported(c, "fmi2GetStringStatus")
}
