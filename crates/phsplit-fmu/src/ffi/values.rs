//! Getting and setting the variables (`fmi2Get*`, `fmi2Set*` of the FMI 2.0 co-simulation C API):
//! the host's arrays of value references and values read, checked and passed to the instance.
//! The instances, the lifecycle and the steps are [`super`]'s.

use super::*;
/// Read `n` value references and values from the host's arrays.
///
/// # Safety
/// The arrays hold `n` elements (or are null with `n == 0`).
unsafe fn slices<'a, T>(
    vr: *const c_uint,
    n: usize,
    v: *const T,
) -> Option<(&'a [c_uint], &'a [T])> {
    if n == 0 {
        return Some((&[], &[]));
    }
    if vr.is_null() || v.is_null() {
        return None;
    }
    // SAFETY: the host's arrays of n elements.
    Some(unsafe {
        (
            std::slice::from_raw_parts(vr, n),
            std::slice::from_raw_parts(v, n),
        )
    })
}

fn get_each<T>(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    out: *mut T,
    what: &str,
    mut f: impl FnMut(&mut Component, u32) -> std::result::Result<T, String>,
) -> Fmi2Status {
    with(c, |comp| {
        if n > 0 && (vr.is_null() || out.is_null()) {
            return comp.fail(&format!("{what}: null array for {n} values"));
        }
        for i in 0..n {
            // SAFETY: the host's arrays of n elements.
            let r = unsafe { *vr.add(i) };
            match f(comp, r) {
                Ok(x) => unsafe { out.add(i).write(x) },
                Err(e) => return comp.fail(&format!("{what}: {e}")),
            }
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *mut f64,
) -> Fmi2Status {
    // Before fmi2ExitInitializationMode (a master reads the initial outputs in initialisation
    // mode): the outputs of the state the parameters set so far give, built once per call.
    let mut provisional: Option<std::result::Result<Instance, String>> = None;
    get_each(c, vr, n, v, "fmi2GetReal", |comp, r| {
        if comp.inst.initialized() {
            return comp.inst.get_real(r);
        }
        let p = provisional.get_or_insert_with(|| {
            let mut p = comp.inst.clone();
            p.initialize(comp.inst.start_time).map(|()| p)
        });
        match p {
            Ok(p) => p.get_real(r),
            Err(e) => Err(e.clone()),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *mut c_int,
) -> Fmi2Status {
    get_each(c, vr, n, v, "fmi2GetInteger", |_, r| {
        Err(format!(
            "this FMU has no Integer variables (value reference {r})"
        ))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *mut c_int,
) -> Fmi2Status {
    get_each(c, vr, n, v, "fmi2GetBoolean", |comp, r| {
        comp.inst.get_boolean(r).map(c_int::from)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *mut *const c_char,
) -> Fmi2Status {
    with(c, |comp| {
        if n > 0 && (vr.is_null() || v.is_null()) {
            return comp.fail("fmi2GetString: null array");
        }
        comp.strings.clear();
        for i in 0..n {
            // SAFETY: the host's arrays of n elements.
            let r = unsafe { *vr.add(i) };
            match comp.inst.get_string(r) {
                Ok(s) => comp
                    .strings
                    .push(CString::new(s.replace('\0', " ")).unwrap_or_default()),
                Err(e) => return comp.fail(&format!("fmi2GetString: {e}")),
            }
        }
        for (i, s) in comp.strings.iter().enumerate() {
            // SAFETY: the host's array of n pointers; the strings live until the next call.
            unsafe { v.add(i).write(s.as_ptr()) };
        }
        OK
    })
}

fn set_each<T: Copy>(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *const T,
    what: &str,
    conv: impl Fn(T) -> std::result::Result<Val, String>,
) -> Fmi2Status {
    with(c, |comp| {
        // SAFETY: the host's arrays of n elements.
        let Some((vrs, vals)) = (unsafe { slices(vr, n, v) }) else {
            return comp.fail(&format!("{what}: null array for {n} values"));
        };
        // All or none: the values are checked before any is kept.
        let mut items = Vec::with_capacity(vrs.len());
        for (r, x) in vrs.iter().zip(vals) {
            match conv(*x) {
                Ok(v) => items.push((*r, v)),
                Err(e) => {
                    return comp.fail(&format!(
                        "{what}: {e} (value reference {r}; none of the {n} values set)"
                    ))
                }
            }
        }
        match comp.inst.set_many(items) {
            Ok(()) => OK,
            Err(e) => comp.fail(&format!("{what}: {e} (none of the {n} values set)")),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *const f64,
) -> Fmi2Status {
    set_each(c, vr, n, v, "fmi2SetReal", |x| {
        if x.is_finite() {
            Ok(Val::Real(x))
        } else {
            Err(format!("values must be finite, got {x}"))
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *const c_int,
) -> Fmi2Status {
    set_each(c, vr, n, v, "fmi2SetInteger", |_| {
        Err("this FMU has no Integer variables".into())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *const c_int,
) -> Fmi2Status {
    set_each(c, vr, n, v, "fmi2SetBoolean", |x| Ok(Val::Boolean(x != 0)))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    v: *const *const c_char,
) -> Fmi2Status {
    set_each(c, vr, n, v, "fmi2SetString", |p| {
        c_str(p)
            .map(Val::String)
            .ok_or_else(|| "null string".to_string())
    })
}
