//! Many engines in one call, for hosts without a job system. With the `parallel` feature the engines are
//! stepped on rayon's pool; without it, one after the other. Hosts that have a job system step engines from
//! their own threads instead (engines are `Send`, and distinct engines share nothing).

use glam::Vec3;

use super::engine::{Engine, validate_step};
use super::error::{Error, Result};
use super::math::Transform;

/// Steps every engine by `dt` with the camera at `camera` and engine `i`'s view reference joint K at
/// `view_references[i]`. Every input is validated before any engine changes: on error nothing has moved.
pub fn step_engines(engines: &mut [&mut Engine], dt: f32, camera: Vec3, view_references: &[Transform]) -> Result<()> {
    if view_references.len() != engines.len() {
        return Err(Error::invalid_argument(format!(
            "one view reference per engine: {} engines, {} view references",
            engines.len(),
            view_references.len()
        )));
    }
    for (i, k) in view_references.iter().enumerate() {
        validate_step(dt, camera, k).map_err(|e| Error::invalid_argument(format!("engine {i}: {}", e.message)))?;
    }
    let step = |engine: &mut Engine, k: &Transform| engine.step(dt, camera, *k).expect("inputs validated above");
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        engines.par_iter_mut().zip(view_references.par_iter()).for_each(|(engine, k)| step(engine, k));
    }
    #[cfg(not(feature = "parallel"))]
    for (engine, k) in engines.iter_mut().zip(view_references) {
        step(engine, k);
    }
    Ok(())
}
