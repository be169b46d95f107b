//! The runtime's WGSL, composed with naga_oil: a pass's shader names the library modules it
//! uses (`#import strandlight::strand_quads::{VertexOut, frame}`), each library module names
//! itself (`#define_import_path strandlight::strand_quads`), and [`shader_module`] links the
//! pass's shader with the modules it imports, recursively, into one naga module. Only the
//! pass's own file declares entry points (an imported module's become plain functions).
//!
//! The point-light strand passes choose their fiber model when they are built: the model's file
//! is composed as the module `strandlight::fiber_model` ([`FIBER_MODEL`]).

use std::borrow::Cow;
use std::collections::HashMap;

use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderLanguage,
    get_preprocessor_data,
};
use wgpu::naga::valid::Capabilities;

/// A WGSL file: its name (in error messages) and its text.
#[derive(Clone, Copy, Debug)]
pub struct Wgsl {
    pub file: &'static str,
    pub source: &'static str,
}

/// The import path of the fiber model a strand shading module is composed with.
pub const FIBER_MODEL: &str = "strandlight::fiber_model";

/// Every library module, each declaring its import path.
const LIBRARY: &[Wgsl] = &[
    Wgsl {
        file: "passes/strand_quads.wgsl",
        source: include_str!("passes/strand_quads.wgsl"),
    },
    Wgsl {
        file: "passes/strand_shading.wgsl",
        source: include_str!("passes/strand_shading.wgsl"),
    },
    Wgsl {
        file: "passes/fullscreen.wgsl",
        source: include_str!("passes/fullscreen.wgsl"),
    },
    Wgsl {
        file: "passes/fiber_frame.wgsl",
        source: include_str!("passes/fiber_frame.wgsl"),
    },
    Wgsl {
        file: "passes/fiber_lut.wgsl",
        source: include_str!("passes/fiber_lut.wgsl"),
    },
    Wgsl {
        file: "passes/table_axis.wgsl",
        source: include_str!("passes/table_axis.wgsl"),
    },
    Wgsl {
        file: "passes/convolution_transmittance.wgsl",
        source: include_str!("passes/convolution_transmittance.wgsl"),
    },
    Wgsl {
        file: "env/view_binding.wgsl",
        source: include_str!("env/view_binding.wgsl"),
    },
    Wgsl {
        file: "env/occupancy_map.wgsl",
        source: include_str!("env/occupancy_map.wgsl"),
    },
    Wgsl {
        file: "env/view_layers.wgsl",
        source: include_str!("env/view_layers.wgsl"),
    },
    Wgsl {
        file: "env/segment_light_samples.wgsl",
        source: include_str!("env/segment_light_samples.wgsl"),
    },
    Wgsl {
        file: "env/head_view.wgsl",
        source: include_str!("env/head_view.wgsl"),
    },
    Wgsl {
        file: "env/visibility_volume.wgsl",
        source: include_str!("env/visibility_volume.wgsl"),
    },
    Wgsl {
        file: "env/table_lookup.wgsl",
        source: include_str!("env/table_lookup.wgsl"),
    },
    Wgsl {
        file: "env/env_shading.wgsl",
        source: include_str!("env/env_shading.wgsl"),
    },
    Wgsl {
        file: "env/skin.wgsl",
        source: include_str!("env/skin.wgsl"),
    },
];

/// The import path a library module declares.
fn import_path(module: &Wgsl) -> String {
    match get_preprocessor_data(module.source).0 {
        Some(path) => path,
        None => panic!("{} declares no #define_import_path", module.file),
    }
}

/// The library module named by an import of `path` (which may end in an item's name).
fn library_module<'a>(
    path: &str,
    library: &'a HashMap<String, Wgsl>,
) -> Option<(&'a str, &'a Wgsl)> {
    let mut candidate = path;
    loop {
        if let Some((name, module)) = library.get_key_value(candidate) {
            return Some((name, module));
        }
        candidate = candidate.rsplit_once("::")?.0;
    }
}

/// Adds to `composer` the modules `source` imports (theirs first), each once.
fn add_imports(composer: &mut Composer, source: &Wgsl, library: &HashMap<String, Wgsl>) {
    for import in get_preprocessor_data(source.source).1 {
        let Some((name, module)) = library_module(&import.import, library) else {
            panic!(
                "{}: no library module provides `{}`",
                source.file, import.import
            )
        };
        if composer.contains_module(name) {
            continue;
        }
        add_imports(composer, module, library);
        let descriptor = ComposableModuleDescriptor {
            source: module.source,
            file_path: module.file,
            language: ShaderLanguage::Wgsl,
            as_name: Some(name.to_string()),
            additional_imports: &[],
            shader_defs: HashMap::new(),
        };
        if let Err(e) = composer.add_composable_module(descriptor) {
            panic!("{}", e.emit_to_string(composer));
        }
    }
}

/// `top` linked with the library modules it imports (and `fiber_model` as [`FIBER_MODEL`]).
/// The shaders are part of the program: a composition error is a bug, and panics with
/// naga_oil's report of the file and line.
pub fn compose(top: &Wgsl, fiber_model: Option<&Wgsl>) -> wgpu::naga::Module {
    let mut library: HashMap<String, Wgsl> = LIBRARY.iter().map(|m| (import_path(m), *m)).collect();
    if let Some(model) = fiber_model {
        library.insert(FIBER_MODEL.to_string(), *model);
    }
    // The device validates the module against its own capabilities when it is created; here
    // every capability is allowed (core WGSL such as pack2x16float needs some).
    let mut composer = Composer::default().with_capabilities(Capabilities::all());
    add_imports(&mut composer, top, &library);
    let descriptor = NagaModuleDescriptor {
        source: top.source,
        file_path: top.file,
        ..Default::default()
    };
    match composer.make_naga_module(descriptor) {
        Ok(module) => module,
        Err(e) => panic!("{}", e.emit_to_string(&composer)),
    }
}

/// [`compose`] made a shader module of `device`.
pub fn shader_module(
    device: &wgpu::Device,
    top: &Wgsl,
    fiber_model: Option<&Wgsl>,
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(top.file),
        source: wgpu::ShaderSource::Naga(Cow::Owned(compose(top, fiber_model))),
    })
}
