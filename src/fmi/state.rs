//! FMU states for both FMI versions: a state is a boxed [`FmuState`]; its pointer
//! goes to the master and comes back in Set, Free and Serialize.

use std::ffi::{c_int, c_void};

use super::slave::FmuState;
use super::{Instance, OK};
use crate::ffi::guard::{put, slice, slice_mut};

type Status = c_int;

/// Saves into a new state, or over the one `*state` points to.
pub(super) fn get_state(inst: &mut Instance, state: *mut *mut c_void) -> Result<Status, String> {
    if state.is_null() {
        return Err("FMUstate is a null pointer".into());
    }
    let saved = inst.component.save_state()?;
    // SAFETY: checked non-null; a non-null *state came from an earlier GetFMUstate.
    unsafe {
        if (*state).is_null() {
            *state = Box::into_raw(Box::new(saved)) as *mut c_void;
        } else {
            *((*state) as *mut FmuState) = saved;
        }
    }
    Ok(OK)
}

/// Restores the state a pointer holds.
pub(super) fn set_state(inst: &mut Instance, state: *mut c_void) -> Result<Status, String> {
    if state.is_null() {
        return Err("FMUstate is a null pointer".into());
    }
    // SAFETY: a state pointer comes from GetFMUstate or DeSerializeFMUstate.
    let state = unsafe { &*(state as *const FmuState) };
    inst.component.restore_state(state)?;
    Ok(OK)
}

/// Frees a state and clears the pointer.
pub(super) fn free_state(state: *mut *mut c_void) -> Result<Status, String> {
    if !state.is_null() {
        // SAFETY: as for set_state; the pointer is cleared after the drop.
        unsafe {
            if !(*state).is_null() {
                drop(Box::from_raw(*state as *mut FmuState));
                *state = std::ptr::null_mut();
            }
        }
    }
    Ok(OK)
}

/// Writes the size of a state's bytes.
pub(super) fn serialised_size(
    inst: &Instance,
    state: *mut c_void,
    size: *mut usize,
) -> Result<Status, String> {
    let bytes = bytes_of(inst, state)?;
    unsafe { put(size, bytes.len(), "size") }?;
    Ok(OK)
}

/// Writes a state's bytes into the master's buffer of `size` bytes.
pub(super) fn serialise(
    inst: &Instance,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Result<Status, String> {
    let data = bytes_of(inst, state)?;
    if data.len() != size {
        return Err(format!("the state has {} bytes, not {size}", data.len()));
    }
    unsafe { slice_mut(bytes, size, "serializedState") }?.copy_from_slice(&data);
    Ok(OK)
}

fn bytes_of(inst: &Instance, state: *mut c_void) -> Result<Vec<u8>, String> {
    if state.is_null() {
        return Err("FMUstate is a null pointer".into());
    }
    // SAFETY: as for set_state.
    let state = unsafe { &*(state as *const FmuState) };
    inst.component.state_to_bytes(state)
}

/// A state from bytes, into a new state or over the one `*state` points to.
pub(super) fn deserialise(
    inst: &mut Instance,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Result<Status, String> {
    let data = unsafe { slice(bytes, size, "serializedState") }?;
    if state.is_null() {
        return Err("FMUstate is a null pointer".into());
    }
    let restored = inst.component.state_from_bytes(data)?;
    // SAFETY: checked non-null; a non-null *state came from an earlier call.
    unsafe {
        if (*state).is_null() {
            *state = Box::into_raw(Box::new(restored)) as *mut c_void;
        } else {
            *((*state) as *mut FmuState) = restored;
        }
    }
    Ok(OK)
}
