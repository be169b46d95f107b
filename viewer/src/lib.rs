//! `strandlight view`: a window on hair lit live, through the same runtime and scene layer as
//! `render`. The window thread handles input and presents at its own pace; a render thread
//! draws a preview and then refines the full frame (progressive); table bakes run in the
//! background while the old tables stay on screen.

mod app;
pub mod display;
pub mod frame;
pub mod gpu_display;
pub use strandlight_scene::orbit;
mod pacing;
mod panel;
pub mod progressive;
pub mod recompute;
pub mod screenshot;
pub mod script;
mod session;
pub mod window_capture;
pub mod worker;

pub use app::{ViewOptions, WindowDevice, run};
pub use session::{RequestTiming, SessionReport};
