//! GPU plumbing shared by the passes: the device, and reading textures back to the CPU.

pub mod bind_layout;
pub mod device;
pub mod readback;

pub use device::{AdapterReport, DeviceError, GpuContext};
pub use readback::{read_buffer, read_texture_rgba};
