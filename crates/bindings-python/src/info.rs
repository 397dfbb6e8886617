//! What this build has compiled in: the set, its model form, the component and pose
//! column names, the tissue stacks.
use needle_haptics::insertion::stacks;
use needle_haptics::model_info;
use pyo3::prelude::*;

/// The names of the compiled-in tissue stacks.
#[pyfunction]
fn stack_names() -> Vec<&'static str> {
    stacks::ALL.iter().map(|s| s.name).collect()
}

pub fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SET", model_info::SET)?;
    m.add("SET_DIR", model_info::SET_DIR)?;
    m.add("COUPLED", model_info::COUPLED)?;
    m.add("FITTED", model_info::FITTED)?;
    m.add("POSE_COLUMNS", crate::poses::COLUMNS.to_vec())?;
    m.add("COMPONENTS", needle_contract::COMPONENTS.to_vec())?;
    m.add_function(wrap_pyfunction!(stack_names, m)?)?;
    m.add_class::<crate::insertion::Trajectory>()?;
    Ok(())
}
