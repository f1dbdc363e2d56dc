//! The FMI 2.0 co-simulation C API over [`crate::instance`] and [`crate::layout`].
//!
//! The types and signatures follow the standard's headers `fmi2TypesPlatform.h` and
//! `fmi2FunctionTypes.h` (FMI 2.0.4, Modelica Association, 2-clause BSD), written out here: the
//! Rust crates that carry those headers (`fmi-sys`) generate their bindings with bindgen at build
//! time, which needs libclang, which this project does not require; and the FMI 3.0 export crate
//! does not cover FMI 2.0. The hosts check the binding: FMPy (ctypes with the standard's
//! prototypes) and OSP's libcosim (C++ against the headers) in `python/tests/test_fmu.py`.
//!
//! Every entry point catches panics (a panic never unwinds into the host: it becomes
//! `fmi2Fatal` with a logged message) and checks its pointers; errors are logged through the
//! host's logger with the message of the model, naming the variable or parameter.
//!
//! # Safety
//! Every entry point is `unsafe`: the host keeps the standard's contract (a component from
//! `fmi2Instantiate`, not yet freed; arrays of the lengths it passes; NUL-terminated strings;
//! states from `fmi2GetFMUstate`). Null pointers are checked and refused.
#![allow(clippy::missing_safety_doc)]

use crate::instance::{Instance, Mode};
use crate::layout::{Layout, Val};
use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

mod values;
pub use values::*;

pub type Fmi2Status = c_int;
pub const OK: Fmi2Status = 0;
pub const DISCARD: Fmi2Status = 2;
pub const ERROR: Fmi2Status = 3;
pub const FATAL: Fmi2Status = 4;

/// `fmi2Type`: model exchange 0, co-simulation 1.
const CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind`.
const LAST_SUCCESSFUL_TIME: c_int = 2;
const TERMINATED: c_int = 3;

/// `fmi2CallbackLogger` (variadic; phsplit passes a message without conversions, its `%`
/// doubled).
type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Fmi2Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Fmi2Status)>,
    component_environment: *mut c_void,
}

/// An instance as the host holds it (`fmi2Component`).
struct Component {
    name: CString,
    logger: Option<Logger>,
    env: *mut c_void,
    logging_on: bool,
    inst: Instance,
    /// The strings handed out by `fmi2GetString`, valid until the next call.
    strings: Vec<CString>,
}

impl Component {
    fn log(&self, status: Fmi2Status, category: &str, msg: &str) {
        if status == OK && !self.logging_on {
            return;
        }
        if let Some(logger) = self.logger {
            let msg = CString::new(msg.replace('%', "%%").replace('\0', " ")).unwrap_or_default();
            let cat = CString::new(category).unwrap_or_default();
            // SAFETY: the host's logger, called with valid C strings as the standard asks.
            unsafe {
                logger(
                    self.env,
                    self.name.as_ptr(),
                    status,
                    cat.as_ptr(),
                    msg.as_ptr(),
                )
            };
        }
    }
    fn fail(&self, msg: &str) -> Fmi2Status {
        self.log(ERROR, "logStatusError", msg);
        ERROR
    }
}

/// Run `f` on the component `c`, catching panics; null components are refused.
fn with(c: *mut c_void, f: impl FnOnce(&mut Component) -> Fmi2Status) -> Fmi2Status {
    if c.is_null() {
        return ERROR;
    }
    // SAFETY: a non-null fmi2Component is a Box<Component> made by fmi2Instantiate and not
    // yet freed (the standard's contract with the host).
    let comp = unsafe { &mut *(c as *mut Component) };
    match catch_unwind(AssertUnwindSafe(|| f(comp))) {
        Ok(s) => s,
        Err(p) => {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            comp.log(
                FATAL,
                "logStatusFatal",
                &format!("internal error in phsplit: {msg}"),
            );
            FATAL
        }
    }
}

fn c_str(p: *const c_char) -> Option<String> {
    if p.is_null() {
        None
    } else {
        // SAFETY: the host passes NUL-terminated strings.
        Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }
}

/// The folder of an `fmuResourceLocation` URI (`file:///a/b`, `file:/a/b`, percent-encoded).
pub fn resource_dir(uri: &str) -> Option<std::path::PathBuf> {
    let rest = uri.strip_prefix("file:")?;
    let path = if let Some(r) = rest.strip_prefix("//") {
        // `file://host/path`: an empty host or localhost.
        let i = r.find('/')?;
        match &r[..i] {
            "" | "localhost" => &r[i..],
            _ => return None,
        }
    } else {
        rest
    };
    let bytes = path.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Some(std::path::PathBuf::from(String::from_utf8(out).ok()?))
}

fn instantiate(
    name: &str,
    fmu_type: c_int,
    guid: Option<String>,
    resources: Option<String>,
    logger: Option<Logger>,
    env: *mut c_void,
    logging_on: bool,
) -> std::result::Result<Box<Component>, (Box<Component>, String)> {
    let layout = Arc::new(Layout::load(toml::Table::new()));
    let mut comp = Box::new(Component {
        name: CString::new(name.replace('\0', " ")).unwrap_or_default(),
        logger,
        env,
        logging_on,
        inst: Instance::new(layout),
        strings: Vec::new(),
    });
    if fmu_type != CO_SIMULATION {
        return Err((
            comp,
            "this FMU is for co-simulation only (fmuType must be fmi2CoSimulation)".into(),
        ));
    }
    let Some(dir) = resources.as_deref().and_then(resource_dir) else {
        return Err((
            comp,
            format!(
                "fmuResourceLocation must be a file: URI of the unpacked resources folder, got {}",
                resources
                    .as_deref()
                    .map_or("none".to_string(), |r| format!("{r:?}"))
            ),
        ));
    };
    let read = |f: &str| std::fs::read_to_string(dir.join(f));
    let fmu = match read("fmu.toml") {
        Ok(t) => t,
        Err(e) => {
            return Err((
                comp,
                format!("cannot read {}: {e}", dir.join("fmu.toml").display()),
            ))
        }
    };
    let vessel = read("vessel.toml").ok();
    let table: toml::Table = match fmu.parse() {
        Ok(t) => t,
        Err(e) => return Err((comp, format!("resources/fmu.toml cannot be read: {e}"))),
    };
    let want = table
        .get("fmu")
        .and_then(|f| f.get("guid"))
        .and_then(|g| g.as_str());
    if let (Some(want), Some(got)) = (want, guid.as_deref()) {
        if want != got {
            return Err((comp, format!("fmuGUID {got:?} is not this FMU's ({want:?}): the modelDescription.xml and the resources come from different exports")));
        }
    }
    match Layout::new(&fmu, vessel.as_deref()) {
        Ok(layout) => {
            comp.inst = Instance::new(Arc::new(layout));
            Ok(comp)
        }
        Err(e) => Err((comp, e)),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> Fmi2Status {
    with(c, |comp| {
        comp.logging_on = logging_on != 0;
        OK
    })
}

/// # Safety
/// `functions` must be null or point to the host's `fmi2CallbackFunctions`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    let (logger, env) = if functions.is_null() {
        (None, std::ptr::null_mut())
    } else {
        // SAFETY: checked non-null; the host's struct.
        let f = unsafe { &*functions };
        (f.logger, f.component_environment)
    };
    let name = c_str(instance_name).unwrap_or_else(|| "phsplit".into());
    let r = catch_unwind(AssertUnwindSafe(|| {
        instantiate(
            &name,
            fmu_type,
            c_str(guid),
            c_str(resource_location),
            logger,
            env,
            logging_on != 0,
        )
    }));
    match r {
        Ok(Ok(comp)) => Box::into_raw(comp) as *mut c_void,
        Ok(Err((comp, msg))) => {
            comp.log(ERROR, "logStatusError", &format!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        }
        Err(_) => std::ptr::null_mut(),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        // SAFETY: made by fmi2Instantiate, freed once (the host's contract).
        let _ = catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Component) }));
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> Fmi2Status {
    with(c, |comp| {
        if comp.inst.mode != Mode::Instantiated {
            return comp.fail(&format!(
                "fmi2SetupExperiment: only after fmi2Instantiate or fmi2Reset (the FMU is in {:?} mode)",
                comp.inst.mode
            ));
        }
        if !start_time.is_finite() {
            return comp.fail(&format!(
                "fmi2SetupExperiment: startTime must be finite, got {start_time}"
            ));
        }
        if stop_time_defined != 0 && !(stop_time.is_finite() && stop_time >= start_time) {
            return comp.fail(&format!(
                "fmi2SetupExperiment: stopTime must be finite and >= startTime {start_time}, got {stop_time}"
            ));
        }
        comp.inst.start_time = start_time;
        comp.inst.stop_time = (stop_time_defined != 0).then_some(stop_time);
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        if comp.inst.mode != Mode::Instantiated {
            return comp.fail(&format!(
                "fmi2EnterInitializationMode: only after fmi2Instantiate or fmi2Reset (the FMU is in {:?} mode)",
                comp.inst.mode
            ));
        }
        comp.inst.mode = Mode::Initialization;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        if comp.inst.mode != Mode::Initialization {
            return comp.fail(&format!(
                "fmi2ExitInitializationMode: only after fmi2EnterInitializationMode (the FMU is in {:?} mode)",
                comp.inst.mode
            ));
        }
        let t0 = comp.inst.start_time;
        match comp.inst.initialize(t0) {
            Ok(()) => OK,
            Err(e) => comp.fail(&format!("fmi2ExitInitializationMode: {e}")),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        comp.inst.mode = Mode::Terminated;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        comp.inst = Instance::new(comp.inst.layout.clone());
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        if state.is_null() {
            return comp.fail("fmi2GetFMUstate: null pointer");
        }
        // SAFETY: the host's pointer to an fmi2FMUstate: null (make a new one) or one of ours.
        unsafe {
            let old = *state;
            if old.is_null() {
                *state = Box::into_raw(Box::new(comp.inst.clone())) as *mut c_void;
            } else {
                *(old as *mut Instance) = comp.inst.clone();
            }
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        if state.is_null() {
            return comp.fail("fmi2SetFMUstate: null state");
        }
        // SAFETY: a state made by fmi2GetFMUstate of this FMU.
        comp.inst = unsafe { &*(state as *const Instance) }.clone();
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Fmi2Status {
    with(c, |_| {
        if !state.is_null() {
            // SAFETY: a state made by fmi2GetFMUstate, freed once.
            unsafe {
                let p = *state;
                if !p.is_null() {
                    drop(Box::from_raw(p as *mut Instance));
                }
                *state = std::ptr::null_mut();
            }
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: *mut c_void,
    _s: *mut c_void,
    _size: *mut usize,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2SerializedFMUstateSize: this FMU does not serialise its state (canSerializeFMUstate is false)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    _s: *mut c_void,
    _b: *mut c_char,
    _n: usize,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2SerializeFMUstate: this FMU does not serialise its state (canSerializeFMUstate is false)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    _b: *const c_char,
    _n: usize,
    _s: *mut *mut c_void,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2DeSerializeFMUstate: this FMU does not serialise its state (canSerializeFMUstate is false)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _u: *const c_uint,
    _nu: usize,
    _z: *const c_uint,
    _nz: usize,
    _dv: *const f64,
    _dz: *mut f64,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail(
            "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative is false)",
        )
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    _vr: *const c_uint,
    _n: usize,
    _order: *const c_int,
    _v: *const f64,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2SetRealInputDerivatives: inputs are held constant over a communication step (canInterpolateInputs is false)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const c_uint,
    _n: usize,
    _order: *const c_int,
    _v: *mut f64,
) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder is 0)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior: c_int,
) -> Fmi2Status {
    with(c, |comp| {
        match comp.inst.mode {
            Mode::Stepping => {}
            Mode::Terminated => return comp.fail("fmi2DoStep: the FMU was terminated"),
            _ => return comp.fail("fmi2DoStep: call fmi2ExitInitializationMode first"),
        }
        match comp
            .inst
            .step(current_communication_point, communication_step_size)
        {
            Ok(()) => OK,
            Err(e) => comp.fail(&format!(
                "fmi2DoStep at t = {current_communication_point}: {e}"
            )),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        comp.fail("fmi2CancelStep: steps are synchronous; there is nothing to cancel")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: *mut c_void,
    _kind: c_int,
    _v: *mut Fmi2Status,
) -> Fmi2Status {
    with(c, |_| DISCARD)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, v: *mut f64) -> Fmi2Status {
    with(c, |comp| {
        if kind == LAST_SUCCESSFUL_TIME && !v.is_null() {
            // SAFETY: the host's pointer.
            unsafe { *v = comp.inst.time };
            OK
        } else {
            DISCARD
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    _kind: c_int,
    _v: *mut c_int,
) -> Fmi2Status {
    with(c, |_| DISCARD)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    kind: c_int,
    v: *mut c_int,
) -> Fmi2Status {
    with(c, |comp| {
        if kind == TERMINATED && !v.is_null() {
            // SAFETY: the host's pointer.
            unsafe { *v = 0 };
            let _ = comp;
            OK
        } else {
            DISCARD
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _v: *mut *const c_char,
) -> Fmi2Status {
    with(c, |_| DISCARD)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_uris() {
        let p = |s: &str| resource_dir(s).map(|p| p.display().to_string());
        assert_eq!(
            p("file:///tmp/a%20b/resources").as_deref(),
            Some("/tmp/a b/resources")
        );
        assert_eq!(p("file:/tmp/x").as_deref(), Some("/tmp/x"));
        assert_eq!(p("file://localhost/tmp/x").as_deref(), Some("/tmp/x"));
        assert_eq!(p("file://server/share"), None);
        assert_eq!(p("http://example.org/x"), None);
        assert_eq!(p("file:///bad%zz"), None);
    }

    /// The C API end to end on the paper's vessel: instantiate from a resource folder, step,
    /// read; null components and bad calls return an error status, never a crash.
    #[test]
    fn the_c_api_steps_and_refuses_bad_calls() {
        let dir = std::env::temp_dir().join(format!("phsplit-fmu-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("fmu.toml"),
            "[fmu]\nkind = \"vessel\"\n[simulation]\nh = 0.5\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("vessel.toml"),
            phsplit_core::model::vessel::PAPER_VESSEL_TOML,
        )
        .unwrap();
        let uri = CString::new(format!("file://{}", dir.display())).unwrap();
        unsafe {
            let c = fmi2Instantiate(
                c"v".as_ptr(),
                CO_SIMULATION,
                std::ptr::null(),
                uri.as_ptr(),
                std::ptr::null(),
                0,
                0,
            );
            assert!(!c.is_null());
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(fmi2EnterInitializationMode(c), OK);
            assert_eq!(fmi2ExitInitializationMode(c), OK);
            // position.x and euler.roll (value references 0 and 3).
            let vr: [c_uint; 2] = [0, 3];
            let mut x = [0.0; 2];
            assert_eq!(fmi2GetReal(c, vr.as_ptr(), 2, x.as_mut_ptr()), OK);
            assert_eq!(x, [723.0, 0.05]);
            assert_eq!(fmi2DoStep(c, 0.0, 1.0, 1), OK);
            assert_eq!(fmi2GetReal(c, vr.as_ptr(), 2, x.as_mut_ptr()), OK);
            assert!(x[1] != 0.05 && x[1].abs() < 0.1, "{x:?}");
            // Wrong communication point, unknown reference, null arrays, null component.
            assert_eq!(fmi2DoStep(c, 5.0, 1.0, 1), ERROR);
            let bad: [c_uint; 1] = [100_000];
            assert_eq!(fmi2GetReal(c, bad.as_ptr(), 1, x.as_mut_ptr()), ERROR);
            assert_eq!(fmi2GetReal(c, std::ptr::null(), 1, x.as_mut_ptr()), ERROR);
            assert_eq!(fmi2DoStep(std::ptr::null_mut(), 0.0, 1.0, 1), ERROR);
            // A model-exchange instantiation is refused.
            let me = fmi2Instantiate(
                c"v".as_ptr(),
                0,
                std::ptr::null(),
                uri.as_ptr(),
                std::ptr::null(),
                0,
                0,
            );
            assert!(me.is_null());
            fmi2FreeInstance(c);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
