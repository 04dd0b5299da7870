//! A retrieval run in-process: a function the host program registers by name (the Python package
//! registers a Python callable), given the same input an external program reads from its file
//! ([`super::external_io`]) and returning the maps such a program writes back. Its products are
//! made and scored exactly as the program's are ([`super::external_io::product`]), so the two
//! paths give the same scores on the same Rrs.
//!
//! ```ron
//! External((name: "oc4", function: Some("oc4"), products: ["chl_mg_m3"]))
//! ```
//!
//! A function runs only what this process's own code registered, so it needs no consent (a
//! program named by a study file does: [`super::external::allowed`]). A study naming a function
//! nobody registered is an error naming it. The function runs on an engine thread; it is not
//! stopped at `time_limit_s` (in-process code cannot be killed) and a cancelled run stops after it
//! returns.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use super::RetrievalError;
use super::external::ExternalSpec;
use super::run::{Product, RetrievalInputs};
use crate::control::RunControl;
use crate::netcdf::{InMemory, Maps};

/// A registered retrieval: the input data set in, the product maps out (or a message).
pub type Function = Arc<dyn Fn(&InMemory, &RunControl) -> Result<Maps, String> + Send + Sync>;

/// (name, registration number, function).
static FUNCTIONS: Mutex<Vec<(String, u64, Function)>> = Mutex::new(Vec::new());
static NEXT: AtomicU64 = AtomicU64::new(1);

/// Register `function` as `name`, replacing any function of that name; returns its registration
/// number (a run's cache key holds it, so a function registered again is a new retrieval).
pub fn register(name: &str, function: Function) -> u64 {
    let number = NEXT.fetch_add(1, Ordering::SeqCst);
    let mut all = FUNCTIONS.lock().unwrap_or_else(PoisonError::into_inner);
    all.retain(|(n, _, _)| n != name);
    all.push((name.to_string(), number, function));
    number
}

/// Forget the function registered as `name`.
pub fn unregister(name: &str) {
    FUNCTIONS.lock().unwrap_or_else(PoisonError::into_inner).retain(|(n, _, _)| n != name);
}

/// The registration number of `name`, if registered.
#[must_use]
pub fn registration(name: &str) -> Option<u64> {
    FUNCTIONS.lock().unwrap_or_else(PoisonError::into_inner).iter().find(|(n, _, _)| n == name).map(|(_, k, _)| *k)
}

/// Run the function `name` over `inputs` and make its product.
pub(super) fn retrieve(
    spec: &ExternalSpec,
    name: &str,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    let error = |message: String| RetrievalError::External { name: spec.name.clone(), message };
    let function = FUNCTIONS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .iter()
        .find(|(n, _, _)| n == name)
        .map(|(_, _, f)| Arc::clone(f))
        .ok_or_else(|| error(format!("no function `{}` is registered in this process", name.escape_debug())))?;
    let used = super::external_io::used_bands(spec, inputs)?;
    let input = super::external_io::input_in_memory(spec, inputs, &used).map_err(&error)?;
    let maps = function(&input, control).map_err(|m| error(format!("the function `{name}` failed: {m}")))?;
    if control.cancelled() {
        return Err(RetrievalError::Cancelled);
    }
    super::external_io::product(spec, inputs, &maps).map_err(error)
}
