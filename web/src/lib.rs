//! The web page: the env-lit frame of a `strandlight web` bundle rendered in a browser through
//! WebGPU, by the same runtime and scene code as `render` (`EnvRenderer::encode_part_into` through
//! `scene::env_frame::lights_call`), refined progressively one light batch per animation
//! frame. `index.html` (at the crate's root) holds the controls and calls [`page::Page`].

pub mod session;

#[cfg(target_arch = "wasm32")]
pub mod page;
