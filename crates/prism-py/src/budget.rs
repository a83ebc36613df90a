//! `prism.set_memory_budget` and `prism.memory_budget`: the most one picture, film or buffer
//! sized by an input may take (the command's `--max-memory`).

use pyo3::prelude::*;

use crate::errors::argument;

/// Sets the memory budget in bytes (at least 64 MiB; 2 GiB unless set): larger requests
/// (a picture, a film, a subdivided mesh) raise `LimitError` before anything is allocated,
/// and each decoded image may take a quarter of it.
#[pyfunction]
pub fn set_memory_budget(bytes: u64) -> PyResult<()> {
    if bytes < prism_math::limits::MIN_MEMORY_BUDGET {
        return Err(argument(format!(
            "bytes: expected at least {} (64 MiB), found {bytes}",
            prism_math::limits::MIN_MEMORY_BUDGET
        )));
    }
    prism_math::limits::set_memory_budget(bytes);
    Ok(())
}

/// The memory budget in bytes.
#[pyfunction]
pub fn memory_budget() -> u64 {
    prism_math::limits::memory_budget()
}
