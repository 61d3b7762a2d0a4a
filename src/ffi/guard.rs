//! What every `extern "C"` entry point of talus goes through: panics caught, pointers
//! checked, strings converted.

use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `f`, turning a panic into `Err` with its message. Nothing unwinds past an
/// entry point.
pub fn catch<R>(f: impl FnOnce() -> Result<R, String>) -> Result<R, String> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(format!("internal error (panic): {what}"))
        }
    }
}

/// A UTF-8 string from a C string, or why not.
///
/// # Safety
/// `p` is null or points to a NUL-terminated string.
pub unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, String> {
    if p.is_null() {
        return Err(format!("{what} is a null pointer"));
    }
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map_err(|_| format!("{what} is not UTF-8"))
}

/// A slice from a C array of `n` elements (a null pointer is accepted for `n == 0`).
///
/// # Safety
/// `p` is null or points to `n` valid elements.
pub unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(format!("{what} is a null pointer"));
    }
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A mutable slice from a C array of `n` elements.
///
/// # Safety
/// `p` is null or points to `n` valid, writable elements.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(format!("{what} is a null pointer"));
    }
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// Writes through an output pointer.
///
/// # Safety
/// `p` is null or valid for a write.
pub unsafe fn put<T>(p: *mut T, value: T, what: &str) -> Result<(), String> {
    if p.is_null() {
        return Err(format!("{what} is a null pointer"));
    }
    unsafe { p.write(value) };
    Ok(())
}
