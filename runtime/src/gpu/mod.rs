//! GPU plumbing shared by the passes: the device, and reading textures back to the CPU.

pub mod bind_layout;
pub mod buffer;
pub mod device;
pub mod limits;
pub mod pass_timer;
pub mod pipeline;
pub mod readback;
pub mod texture;

pub use device::{AdapterReport, DeviceError, GpuContext};
pub use limits::{GpuLimits, LimitError};
pub use pass_timer::PassTimer;
pub use readback::{
    data_readbacks_on_this_thread, data_readbacks_so_far, read_buffer, read_texture_rgba,
    readbacks_so_far,
};
