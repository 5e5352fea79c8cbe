//! A compiled model's library, loaded: its C functions (`shim.rs.in`) behind the runtime's
//! `Dynamics` contract, so that runs, sweeps and the functions one call each work on it as
//! on the models compiled into the package.

use super::Failure;
use crate::errors::Location;
use camchain_runtime::{
    ArticulatedTerms, ContactGeometry, ContactKinematics, Dynamics, Energy, Flank, ModelInfo,
    VelocityTerms,
};
use libloading::Library;
use std::path::Path;
use std::sync::Arc;

/// The ABI version of `shim.rs.in` (its `camchain_abi()`).
pub const ABI: u32 = 4;

type Ptr = *const Handle;
type P = *const f64;
type M = *mut f64;

/// The library's instance type, opaque here.
#[repr(C)]
pub struct Handle {
    _private: [u8; 0],
}

/// The library's functions.
#[derive(Clone, Copy)]
struct Api {
    new:
        unsafe extern "C" fn(*const u8, usize, P, usize, *mut u8, usize, *mut usize) -> *mut Handle,
    free: unsafe extern "C" fn(*mut Handle),
    parameter_values: unsafe extern "C" fn(Ptr, M),
    mass_matrix: unsafe extern "C" fn(Ptr, P, M),
    inertial_forces: unsafe extern "C" fn(Ptr, P, P, M),
    applied_forces: unsafe extern "C" fn(Ptr, f64, P, P, M),
    loop_points: unsafe extern "C" fn(Ptr, P, M),
    constraint: unsafe extern "C" fn(Ptr, P, M),
    constraint_jacobian: unsafe extern "C" fn(Ptr, P, M),
    constraint_bias: unsafe extern "C" fn(Ptr, P, P, M),
    contact_geometry: unsafe extern "C" fn(Ptr, P, P, *mut ContactGeometry),
    contact_kinematics: unsafe extern "C" fn(Ptr, P, P, usize, *mut ContactGeometry, M, M),
    prescribed: unsafe extern "C" fn(Ptr, f64, M, M, M),
    energy: unsafe extern "C" fn(Ptr, P, P, M),
    damper_power: unsafe extern "C" fn(Ptr, P) -> f64,
    load_power: unsafe extern "C" fn(Ptr, f64, P, P) -> f64,
    groove_flank: unsafe extern "C" fn(Ptr, P, usize) -> i32,
    equations: unsafe extern "C" fn(Ptr, f64, P, P, M, M, M),
    constraint_terms: unsafe extern "C" fn(Ptr, P, P, M, M),
    cache_len: unsafe extern "C" fn(Ptr) -> usize,
    position_terms: unsafe extern "C" fn(Ptr, P, M, M, M),
    velocity_terms: unsafe extern "C" fn(Ptr, f64, P, P, P, M, M, M, M),
    articulated_len: unsafe extern "C" fn(Ptr) -> usize,
    articulated_rows: unsafe extern "C" fn(Ptr) -> usize,
    articulated_terms: unsafe extern "C" fn(Ptr, f64, P, P, P, M, M, M, M, P, usize, M),
    articulated_response: unsafe extern "C" fn(Ptr, P, P, M, M),
}

/// A compiled model's library, kept loaded while any instance of it lives (each holds an
/// `Arc` of it; the last one dropped unloads the code).
pub struct Loaded {
    _library: Library,
    api: Api,
}

impl Loaded {
    /// Loads the library and checks its ABI version.
    pub fn open(path: &Path) -> Result<Arc<Loaded>, Failure> {
        let fail = |e: String| Failure::Load(format!("{}: {e}", path.display()));
        // SAFETY: a library this package wrote and compiled from shim.rs.in; its
        // initialisers are Rust's (none of its own).
        let library = unsafe { Library::new(path) }.map_err(|e| fail(e.to_string()))?;
        macro_rules! get {
            ($name:literal) => {
                // SAFETY: the symbol's type is the one shim.rs.in of ABI `ABI` defines.
                *unsafe { library.get(concat!("camchain_", $name, "\0").as_bytes()) }
                    .map_err(|e| fail(e.to_string()))?
            };
        }
        let abi: unsafe extern "C" fn() -> u32 = get!("abi");
        // SAFETY: no arguments, returns a number.
        let version = unsafe { abi() };
        if version != ABI {
            return Err(fail(format!(
                "ABI {version}, this package reads {ABI}: compile the model again"
            )));
        }
        let api = Api {
            new: get!("new"),
            free: get!("free"),
            parameter_values: get!("parameter_values"),
            mass_matrix: get!("mass_matrix"),
            inertial_forces: get!("inertial_forces"),
            applied_forces: get!("applied_forces"),
            loop_points: get!("loop_points"),
            constraint: get!("constraint"),
            constraint_jacobian: get!("constraint_jacobian"),
            constraint_bias: get!("constraint_bias"),
            contact_geometry: get!("contact_geometry"),
            contact_kinematics: get!("contact_kinematics"),
            prescribed: get!("prescribed"),
            energy: get!("energy"),
            damper_power: get!("damper_power"),
            load_power: get!("load_power"),
            groove_flank: get!("groove_flank"),
            equations: get!("equations"),
            constraint_terms: get!("constraint_terms"),
            cache_len: get!("cache_len"),
            position_terms: get!("position_terms"),
            velocity_terms: get!("velocity_terms"),
            articulated_len: get!("articulated_len"),
            articulated_rows: get!("articulated_rows"),
            articulated_terms: get!("articulated_terms"),
            articulated_response: get!("articulated_response"),
        };
        Ok(Arc::new(Loaded {
            _library: library,
            api,
        }))
    }

    /// An instance with these parameter values (over the file's), checked by the generated
    /// code as the build checks the file.
    pub fn instance(
        self: &Arc<Self>,
        info: &ModelInfo,
        values: &[(String, f64)],
    ) -> Result<Compiled, Location> {
        let names: Vec<&str> = values.iter().map(|(n, _)| n.as_str()).collect();
        let names = names.join("\n");
        let numbers: Vec<f64> = values.iter().map(|(_, v)| *v).collect();
        let mut error = vec![0u8; 4096];
        let mut error_len = 0usize;
        // SAFETY: the buffers have the lengths passed with them.
        let handle = unsafe {
            (self.api.new)(
                names.as_ptr(),
                names.len(),
                numbers.as_ptr(),
                numbers.len(),
                error.as_mut_ptr(),
                error.len(),
                &mut error_len,
            )
        };
        if handle.is_null() {
            let text = String::from_utf8_lossy(&error[..error_len.min(error.len())]).into_owned();
            let mut parts = text.splitn(5, '\t');
            let mut next = || parts.next().unwrap_or_default().to_string();
            let (file, line, column, field, message) = (next(), next(), next(), next(), next());
            return Err(Location {
                file,
                line: line.parse().unwrap_or(0),
                column: column.parse().unwrap_or(0),
                field,
                message,
            });
        }
        let mut parameters = vec![0.0; info.parameters.len()];
        // SAFETY: one value per run-time parameter, as the model's info lists them.
        unsafe { (self.api.parameter_values)(handle, parameters.as_mut_ptr()) };
        Ok(Compiled {
            loaded: Arc::clone(self),
            handle,
            info: info.clone(),
            parameters,
        })
    }
}

/// One instance of a compiled model: what a run integrates.
pub struct Compiled {
    loaded: Arc<Loaded>,
    handle: *mut Handle,
    /// The model's description: the numeric reference's of the same file (the same
    /// derivation's, as the tests of generated against numeric code check).
    info: ModelInfo,
    parameters: Vec<f64>,
}

// SAFETY: the generated model is `Send + Sync` (plain data, no interior mutability), and
// the library outlives the handle (the handle holds the `Arc`).
unsafe impl Send for Compiled {}
unsafe impl Sync for Compiled {}

impl Drop for Compiled {
    fn drop(&mut self) {
        // SAFETY: made by `new`, freed once.
        unsafe { (self.loaded.api.free)(self.handle) };
    }
}

impl Compiled {
    fn n(&self) -> usize {
        self.info.n()
    }
}

/// Checks a slice's length before its pointer crosses to the library.
fn len(slice: &[f64], n: usize) {
    assert!(
        slice.len() >= n,
        "a buffer of {} for {n} values",
        slice.len()
    );
}

impl Dynamics for Compiled {
    fn info(&self) -> &ModelInfo {
        &self.info
    }

    fn parameter_values(&self) -> &[f64] {
        &self.parameters
    }

    fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(m, n * n);
        // SAFETY: lengths checked above, as for every call below.
        unsafe { (self.loaded.api.mass_matrix)(self.handle, q.as_ptr(), m.as_mut_ptr()) }
    }

    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        len(f, n);
        unsafe {
            (self.loaded.api.inertial_forces)(self.handle, q.as_ptr(), qd.as_ptr(), f.as_mut_ptr())
        }
    }

    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        len(out, n);
        unsafe {
            (self.loaded.api.applied_forces)(
                self.handle,
                t,
                q.as_ptr(),
                qd.as_ptr(),
                out.as_mut_ptr(),
            )
        }
    }

    fn loop_points(&self, q: &[f64], out: &mut [[f64; 3]]) {
        len(q, self.n());
        assert!(out.len() >= 2 * self.info.loops.len());
        unsafe {
            (self.loaded.api.loop_points)(self.handle, q.as_ptr(), out.as_mut_ptr() as *mut f64)
        }
    }

    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        len(q, self.n());
        len(h, self.info.n_constraints());
        unsafe { (self.loaded.api.constraint)(self.handle, q.as_ptr(), h.as_mut_ptr()) }
    }

    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(j, n * self.info.n_constraints());
        unsafe { (self.loaded.api.constraint_jacobian)(self.handle, q.as_ptr(), j.as_mut_ptr()) }
    }

    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        len(c, self.info.n_constraints());
        unsafe {
            (self.loaded.api.constraint_bias)(self.handle, q.as_ptr(), qd.as_ptr(), c.as_mut_ptr())
        }
    }

    fn contact_geometry(&self, q: &[f64], qd: &[f64], out: &mut [ContactGeometry]) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        assert!(out.len() >= self.info.n_contacts());
        unsafe {
            (self.loaded.api.contact_geometry)(
                self.handle,
                q.as_ptr(),
                qd.as_ptr(),
                out.as_mut_ptr(),
            )
        }
    }

    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        k: usize,
        out: &mut ContactKinematics,
    ) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        let mut scalars = [out.x, out.y, out.z, out.conv1, out.conv2, out.conv3];
        let mut j = vec![0.0; 3 * n];
        for (part, source) in j.chunks_mut(n).zip([&out.j1, &out.j2, &out.j3]) {
            let m = source.len().min(n);
            part[..m].copy_from_slice(&source[..m]);
        }
        unsafe {
            (self.loaded.api.contact_kinematics)(
                self.handle,
                q.as_ptr(),
                qd.as_ptr(),
                k,
                &mut out.geometry,
                scalars.as_mut_ptr(),
                j.as_mut_ptr(),
            )
        }
        [out.x, out.y, out.z, out.conv1, out.conv2, out.conv3] = scalars;
        out.j1 = j[..n].to_vec();
        out.j2 = j[n..2 * n].to_vec();
        out.j3 = j[2 * n..].to_vec();
    }

    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        len(qdd, n);
        unsafe {
            (self.loaded.api.prescribed)(
                self.handle,
                t,
                q.as_mut_ptr(),
                qd.as_mut_ptr(),
                qdd.as_mut_ptr(),
            )
        }
    }

    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let n = self.n();
        len(q, n);
        len(qd, n);
        let mut out = [0.0; 3];
        unsafe { (self.loaded.api.energy)(self.handle, q.as_ptr(), qd.as_ptr(), out.as_mut_ptr()) }
        Energy {
            kinetic: out[0],
            gravity: out[1],
            spring: out[2],
        }
    }

    fn damper_power(&self, qd: &[f64]) -> f64 {
        len(qd, self.n());
        unsafe { (self.loaded.api.damper_power)(self.handle, qd.as_ptr()) }
    }

    fn load_power(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        let n = self.n();
        len(q, n);
        len(qd, n);
        unsafe { (self.loaded.api.load_power)(self.handle, t, q.as_ptr(), qd.as_ptr()) }
    }

    fn groove_flank(&self, q: &[f64], k: usize) -> Option<Flank> {
        len(q, self.n());
        match unsafe { (self.loaded.api.groove_flank)(self.handle, q.as_ptr(), k) } {
            1 => Some(Flank::Inner),
            2 => Some(Flank::Outer),
            _ => None,
        }
    }

    fn equations(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        m: &mut [f64],
        f: &mut [f64],
        applied: &mut [f64],
    ) {
        let n = self.n();
        len(q, n);
        len(qd, n);
        len(m, n * n);
        len(f, n);
        len(applied, n);
        unsafe {
            (self.loaded.api.equations)(
                self.handle,
                t,
                q.as_ptr(),
                qd.as_ptr(),
                m.as_mut_ptr(),
                f.as_mut_ptr(),
                applied.as_mut_ptr(),
            )
        }
    }

    fn constraint_terms(&self, q: &[f64], qd: &[f64], j: &mut [f64], c: &mut [f64]) {
        let (n, m) = (self.n(), self.info.n_constraints());
        len(q, n);
        len(qd, n);
        len(j, m * n);
        len(c, m);
        unsafe {
            (self.loaded.api.constraint_terms)(
                self.handle,
                q.as_ptr(),
                qd.as_ptr(),
                j.as_mut_ptr(),
                c.as_mut_ptr(),
            )
        }
    }

    fn cache_len(&self) -> usize {
        unsafe { (self.loaded.api.cache_len)(self.handle) }
    }

    fn position_terms(&self, q: &[f64], h: &mut [f64], j: &mut [f64], cache: &mut [f64]) {
        let (n, m) = (self.n(), self.info.n_constraints());
        len(q, n);
        len(h, m);
        len(j, m * n);
        len(cache, self.cache_len());
        unsafe {
            (self.loaded.api.position_terms)(
                self.handle,
                q.as_ptr(),
                h.as_mut_ptr(),
                j.as_mut_ptr(),
                cache.as_mut_ptr(),
            )
        }
    }

    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], cache: &[f64], out: VelocityTerms) {
        let (n, m) = (self.n(), self.info.n_constraints());
        len(q, n);
        len(qd, n);
        len(cache, self.cache_len());
        len(out.mass, n * n);
        len(out.inertial, n);
        len(out.applied, n);
        len(out.bias, m);
        unsafe {
            (self.loaded.api.velocity_terms)(
                self.handle,
                t,
                q.as_ptr(),
                qd.as_ptr(),
                cache.as_ptr(),
                out.mass.as_mut_ptr(),
                out.inertial.as_mut_ptr(),
                out.applied.as_mut_ptr(),
                out.bias.as_mut_ptr(),
            )
        }
    }

    fn articulated_len(&self) -> usize {
        // SAFETY: the handle is live while self is.
        unsafe { (self.loaded.api.articulated_len)(self.handle) }
    }

    fn articulated_terms(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        cache: &[f64],
        out: ArticulatedTerms<'_>,
    ) {
        let (n, m) = (self.n(), self.info.n_constraints());
        len(q, n);
        len(qd, n);
        len(cache, self.cache_len());
        len(out.qdd, n);
        len(out.drive, n);
        len(out.bias, m);
        // None (a null pointer, ABI 4) when the response will not be called.
        let factors = if out.factors.is_empty() {
            std::ptr::null_mut()
        } else {
            len(out.factors, self.articulated_len());
            out.factors.as_mut_ptr()
        };
        assert!(
            out.row.is_empty() || out.row.len() == n,
            "a constraint row of {} for {n} values",
            out.row.len()
        );
        let mut solved = [0.0; 2];
        // SAFETY: every buffer checked for the lengths the library reads and writes.
        unsafe {
            (self.loaded.api.articulated_terms)(
                self.handle,
                t,
                q.as_ptr(),
                qd.as_ptr(),
                cache.as_ptr(),
                out.qdd.as_mut_ptr(),
                out.drive.as_mut_ptr(),
                out.bias.as_mut_ptr(),
                factors,
                out.row.as_ptr(),
                out.row.len(),
                solved.as_mut_ptr(),
            )
        }
        out.solved.lambda = solved[0];
        out.solved.delassus = solved[1];
    }

    fn articulated_rows(&self) -> usize {
        // SAFETY: the handle is live while self is.
        unsafe { (self.loaded.api.articulated_rows)(self.handle) }
    }

    fn articulated_response(
        &self,
        factors: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
        drive: &mut [f64],
    ) {
        let n = self.n();
        len(factors, self.articulated_len());
        len(tau, n);
        len(qdd, n);
        len(drive, n);
        // SAFETY: every buffer checked for the lengths the library reads and writes.
        unsafe {
            (self.loaded.api.articulated_response)(
                self.handle,
                factors.as_ptr(),
                tau.as_ptr(),
                qdd.as_mut_ptr(),
                drive.as_mut_ptr(),
            )
        }
    }
}
