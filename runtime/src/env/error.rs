//! Why an env-lit frame could not be rendered.

use super::tables::EnvTableError;
use super::view_visibility::OccupancyError;
use crate::gpu::limits::LimitError;
use crate::gpu::readback::ReadbackError;
use crate::passes::convolution_depth::DodmSettingsError;
use crate::passes::strand_geometry::TooManyPoints;
use crate::visibility::VisibilityVolumeError;

#[derive(Debug, thiserror::Error)]
pub enum EnvRenderError {
    #[error("the environment has no lights")]
    NoLights,
    #[error(
        "no frame of this size and these lights was prepared: call HairRenderer::prepare with \
         the frame first"
    )]
    NotPrepared,
    #[error("light {index}: {problem}")]
    BadLight { index: usize, problem: String },
    #[error(transparent)]
    Settings(#[from] DodmSettingsError),
    #[error(transparent)]
    Table(#[from] EnvTableError),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error("forward-scattering grid: {0}")]
    Grid(String),
    #[error(transparent)]
    Transparency(#[from] OccupancyError),
    #[error(transparent)]
    TooManyPoints(#[from] TooManyPoints),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
    #[error(transparent)]
    VisibilityVolume(#[from] VisibilityVolumeError),
}
