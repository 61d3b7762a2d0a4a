//! The FMI 3.0 Co-Simulation entry points (all 75 functions of the standard's
//! header; see the [module docs](super)). Value references are the variable
//! indices; vectors and mesh arrays are FMI 3 arrays, flattened row-major.

use std::ffi::{c_char, c_int, c_void};

use super::state::{deserialise, free_state, get_state, serialise, serialised_size, set_state};
use super::{
    ERROR, Fmi3Logger, Instance, LogSink, OK, free_instance, log_to, on_instance, resource_dir,
    unsupported,
};
use crate::cosim::{Mode, VarRef};
use crate::ffi::guard::{catch, put, slice, slice_mut, text};

type Instance3 = *mut c_void;
type Status = c_int;
type ValueReference = u32;

/// The elements addressed by value references, checked against `n_values`.
fn refs(inst: &Instance, vr: &[ValueReference], n_values: usize) -> Result<Vec<VarRef>, String> {
    let vars = inst.component.variables();
    let mut out = Vec::with_capacity(n_values);
    for &v in vr {
        let var = v as usize;
        let size = vars
            .get(var)
            .ok_or_else(|| format!("unknown value reference {v}"))?
            .size;
        out.extend((0..size).map(|element| VarRef { var, element }));
    }
    if out.len() != n_values {
        return Err(format!(
            "the value references address {} values, but nValues is {n_values}",
            out.len()
        ));
    }
    Ok(out)
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: Instance3,
    logging_on: bool,
    _n: usize,
    _categories: *const *const c_char,
) -> Status {
    on_instance(instance, "fmi3SetDebugLogging", |inst| {
        inst.logging_on = logging_on;
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    logging_on: bool,
    event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const ValueReference,
    _n_required_intermediate: usize,
    environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
    _intermediate_update: *const c_void,
) -> Instance3 {
    let sink = LogSink::Fmi3(log_message, environment);
    let name = unsafe { text(instance_name, "instanceName") }
        .unwrap_or("talus")
        .to_string();
    let created = catch(|| {
        if event_mode_used {
            return Err("talus has no event mode".into());
        }
        let token = unsafe { text(token, "instantiationToken") }?;
        let path = unsafe { text(resource_path, "resourcePath") }?;
        Instance::create(&name, token, resource_dir(path), sink, logging_on)
    });
    match created {
        Ok(inst) => Box::into_raw(Box::new(inst)) as Instance3,
        Err(message) => {
            log_to(
                sink,
                &name,
                ERROR,
                "logStatusError",
                &format!("fmi3InstantiateCoSimulation: {message}"),
            );
            std::ptr::null_mut()
        }
    }
}

fn refuse_instantiation(
    name: *const c_char,
    environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
    kind: &str,
) -> Instance3 {
    let name = unsafe { text(name, "instanceName") }.unwrap_or("talus");
    let message = format!("talus is a co-simulation FMU; {kind} is not offered");
    log_to(
        LogSink::Fmi3(log_message, environment),
        name,
        ERROR,
        "logStatusError",
        &message,
    );
    std::ptr::null_mut()
}

/// Not offered: logs why and returns null.
///
/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
) -> Instance3 {
    refuse_instantiation(instance_name, environment, log_message, "model exchange")
}

/// Not offered: logs why and returns null.
///
/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    log_message: Option<Fmi3Logger>,
    _clock_update: *const c_void,
    _lock: *const c_void,
    _unlock: *const c_void,
) -> Instance3 {
    refuse_instantiation(
        instance_name,
        environment,
        log_message,
        "scheduled execution",
    )
}

/// # Safety
/// `instance` comes from fmi3InstantiateCoSimulation and is not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: Instance3) {
    free_instance(instance);
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: Instance3,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: bool,
    _stop_time: f64,
) -> Status {
    on_instance(instance, "fmi3EnterInitializationMode", |inst| {
        inst.component
            .enter_initialization_mode(start_time)
            .map_err(|e| e.to_string())?;
        inst.log_warnings();
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: Instance3) -> Status {
    on_instance(instance, "fmi3ExitInitializationMode", |inst| {
        inst.component
            .exit_initialization_mode()
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// In co-simulation without event mode the instance is in step mode after
/// initialisation; this only confirms it.
///
/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: Instance3) -> Status {
    on_instance(instance, "fmi3EnterStepMode", |inst| {
        if inst.component.mode() == Mode::Step {
            Ok(OK)
        } else {
            Err(format!("not allowed in {} mode", inst.component.mode()))
        }
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: Instance3) -> Status {
    on_instance(instance, "fmi3Terminate", |inst| {
        inst.component.terminate().map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: Instance3) -> Status {
    on_instance(instance, "fmi3Reset", |inst| {
        inst.component.reset()?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3GetFloat64", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let out = unsafe { slice_mut(values, n_values, "values") }?;
        inst.component
            .get_real(&refs, out)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3SetFloat64", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let values = unsafe { slice(values, n_values, "values") }?;
        inst.component
            .set_real(&refs, values)
            .map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *mut i32,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3GetInt32", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let mut wide = vec![0i64; n_values];
        inst.component
            .get_integer(&refs, &mut wide)
            .map_err(|e| e.to_string())?;
        let out = unsafe { slice_mut(values, n_values, "values") }?;
        for (o, w) in out.iter_mut().zip(wide) {
            *o = w.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
        }
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *const i32,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3SetInt32", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let values: Vec<i64> = unsafe { slice(values, n_values, "values") }?
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
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetString(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *mut *const c_char,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3GetString", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let strings = inst
            .component
            .get_string(&refs)
            .map_err(|e| e.to_string())?;
        let out = unsafe { slice_mut(values, n_values, "values") }?;
        out.copy_from_slice(&inst.hand_out(strings));
        Ok(OK)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetString(
    instance: Instance3,
    vr: *const ValueReference,
    nvr: usize,
    values: *const *const c_char,
    n_values: usize,
) -> Status {
    on_instance(instance, "fmi3SetString", |inst| {
        let refs = refs(
            inst,
            unsafe { slice(vr, nvr, "valueReferences") }?,
            n_values,
        )?;
        let pointers = unsafe { slice(values, n_values, "values") }?;
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
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(instance: Instance3, state: *mut *mut c_void) -> Status {
    on_instance(instance, "fmi3GetFMUState", |inst| get_state(inst, state))
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(instance: Instance3, state: *mut c_void) -> Status {
    on_instance(instance, "fmi3SetFMUState", |inst| set_state(inst, state))
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(instance: Instance3, state: *mut *mut c_void) -> Status {
    on_instance(instance, "fmi3FreeFMUState", |_| free_state(state))
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: Instance3,
    state: *mut c_void,
    size: *mut usize,
) -> Status {
    on_instance(instance, "fmi3SerializedFMUStateSize", |inst| {
        serialised_size(inst, state, size)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: Instance3,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Status {
    on_instance(instance, "fmi3SerializeFMUState", |inst| {
        serialise(inst, state, bytes, size)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: Instance3,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    on_instance(instance, "fmi3DeserializeFMUState", |inst| {
        deserialise(inst, bytes, size, state)
    })
}

/// # Safety
/// FMI 3.0 calling conventions.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: Instance3,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_prior: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    on_instance(instance, "fmi3DoStep", |inst| {
        let result = inst
            .component
            .do_step(current_communication_point, communication_step_size);
        let t = inst.component.time().unwrap_or(current_communication_point);
        for (p, what) in [
            (event_handling_needed, "eventHandlingNeeded"),
            (terminate_simulation, "terminateSimulation"),
            (early_return, "earlyReturn"),
        ] {
            if !p.is_null() {
                unsafe { put(p, false, what) }?;
            }
        }
        if !last_successful_time.is_null() {
            unsafe { put(last_successful_time, t, "lastSuccessfulTime") }?;
        }
        result.map_err(|e| e.to_string())?;
        Ok(OK)
    })
}

/// Functions talus does not support: each logs why and returns fmi3Error.
macro_rules! unsupported_functions {
    ($($name:ident($($ty:ty),*);)*) => {$(
        /// Not supported: logs why and returns fmi3Error.
        ///
        /// # Safety
        /// FMI 3.0 calling conventions.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(instance: Instance3, $(_: $ty),*) -> Status {
            unsupported(instance, stringify!($name))
        }
    )*};
}

type Vr = *const ValueReference;

unsupported_functions! {
    fmi3EnterEventMode();
    fmi3GetFloat32(Vr, usize, *mut f32, usize);
    fmi3GetInt8(Vr, usize, *mut i8, usize);
    fmi3GetUInt8(Vr, usize, *mut u8, usize);
    fmi3GetInt16(Vr, usize, *mut i16, usize);
    fmi3GetUInt16(Vr, usize, *mut u16, usize);
    fmi3GetUInt32(Vr, usize, *mut u32, usize);
    fmi3GetInt64(Vr, usize, *mut i64, usize);
    fmi3GetUInt64(Vr, usize, *mut u64, usize);
    fmi3GetBoolean(Vr, usize, *mut bool, usize);
    fmi3GetBinary(Vr, usize, *mut usize, *mut *const u8, usize);
    fmi3GetClock(Vr, usize, *mut bool);
    fmi3SetFloat32(Vr, usize, *const f32, usize);
    fmi3SetInt8(Vr, usize, *const i8, usize);
    fmi3SetUInt8(Vr, usize, *const u8, usize);
    fmi3SetInt16(Vr, usize, *const i16, usize);
    fmi3SetUInt16(Vr, usize, *const u16, usize);
    fmi3SetUInt32(Vr, usize, *const u32, usize);
    fmi3SetInt64(Vr, usize, *const i64, usize);
    fmi3SetUInt64(Vr, usize, *const u64, usize);
    fmi3SetBoolean(Vr, usize, *const bool, usize);
    fmi3SetBinary(Vr, usize, *const usize, *const *const u8, usize);
    fmi3SetClock(Vr, usize, *const bool);
    fmi3GetNumberOfVariableDependencies(ValueReference, *mut usize);
    fmi3GetVariableDependencies(ValueReference, *mut usize, *mut ValueReference, *mut usize, *mut c_int, usize);
    fmi3GetDirectionalDerivative(Vr, usize, Vr, usize, *const f64, usize, *mut f64, usize);
    fmi3GetAdjointDerivative(Vr, usize, Vr, usize, *const f64, usize, *mut f64, usize);
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3GetIntervalDecimal(Vr, usize, *mut f64, *mut c_int);
    fmi3GetIntervalFraction(Vr, usize, *mut u64, *mut u64, *mut c_int);
    fmi3GetShiftDecimal(Vr, usize, *mut f64);
    fmi3GetShiftFraction(Vr, usize, *mut u64, *mut u64);
    fmi3SetIntervalDecimal(Vr, usize, *const f64);
    fmi3SetIntervalFraction(Vr, usize, *const u64, *const u64);
    fmi3SetShiftDecimal(Vr, usize, *const f64);
    fmi3SetShiftFraction(Vr, usize, *const u64, *const u64);
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(*mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64);
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(bool, *mut bool, *mut bool);
    fmi3SetTime(f64);
    fmi3SetContinuousStates(*const f64, usize);
    fmi3GetContinuousStateDerivatives(*mut f64, usize);
    fmi3GetEventIndicators(*mut f64, usize);
    fmi3GetContinuousStates(*mut f64, usize);
    fmi3GetNominalsOfContinuousStates(*mut f64, usize);
    fmi3GetNumberOfEventIndicators(*mut usize);
    fmi3GetNumberOfContinuousStates(*mut usize);
    fmi3GetOutputDerivatives(Vr, usize, *const i32, *mut f64, usize);
    fmi3ActivateModelPartition(ValueReference, f64);
}
