//! Pipelines as the passes build them: every render pass draws strand quads (a triangle list
//! expanded in the vertex stage from storage buffers, both faces seen, no vertex buffers), and
//! every compute pass runs one WGSL entry point. What differs between passes (entry points,
//! targets, depth test, blending) is what a pass states; the rest is written once here.

/// Builds `a` and `b` at the same time where the target has threads (one after the other in a
/// browser). A software adapter compiles each pipeline on the CPU when it is created: lavapipe
/// took 0.47 s for the env-lit renderer's pipelines one after another on 2 cores.
pub fn build_both<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        std::thread::scope(|s| {
            let b = s.spawn(b);
            let a = a();
            (a, b.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
        })
    }
    #[cfg(target_arch = "wasm32")]
    {
        (a(), b())
    }
}

/// A render pipeline compiled when a pass first draws with it. A frame uses few of a renderer's
/// pipelines (the opaque view's or the layered one's, a benchmark's counters), and every
/// pipeline compiled up front delayed the first picture: the page's first preview came 1.4 s
/// sooner with two view pipelines fewer to compile (SwiftShader in headless Chromium).
pub struct LazyPipeline {
    pipeline: std::sync::OnceLock<wgpu::RenderPipeline>,
    build: Box<dyn Fn() -> wgpu::RenderPipeline + Send + Sync>,
}

impl LazyPipeline {
    pub fn new(build: impl Fn() -> wgpu::RenderPipeline + Send + Sync + 'static) -> Self {
        Self {
            pipeline: std::sync::OnceLock::new(),
            build: Box::new(build),
        }
    }

    /// The pipeline, compiled now if no pass has used it yet.
    pub fn get(&self) -> &wgpu::RenderPipeline {
        self.pipeline.get_or_init(&self.build)
    }
}

/// A render pipeline that draws strand quads.
pub struct StrandDraw<'a> {
    pub label: &'a str,
    pub layout: &'a wgpu::PipelineLayout,
    pub shader: &'a wgpu::ShaderModule,
    pub vertex_entry: &'a str,
    /// The fragment entry point and its colour targets; `None` for a depth-only pass.
    pub fragment: Option<(&'a str, &'a [Option<wgpu::ColorTargetState>])>,
    pub depth: Option<wgpu::DepthStencilState>,
}

impl StrandDraw<'_> {
    pub fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.shader,
                entry_point: Some(self.vertex_entry),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: self.fragment.map(|(entry, targets)| wgpu::FragmentState {
                module: self.shader,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets,
            }),
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                // A fiber is a ribbon facing the camera or the light: either winding is a hit.
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: self.depth.clone(),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// A depth test against `format`, writing the depth or not.
pub fn depth_test(
    format: wgpu::TextureFormat,
    write: bool,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// Premultiplied colour over what is there: src + (1 − src.a)·dst, for colour and alpha.
pub const PREMULTIPLIED_OVER: wgpu::BlendState = {
    let over = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::BlendState {
        color: over,
        alpha: over,
    }
};

/// Colour and alpha added to what is there: sums over lights, layers or fragments.
pub const ADDITIVE: wgpu::BlendState = {
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::BlendState {
        color: add,
        alpha: add,
    }
};

/// A colour target of `format` that `blend`s (or overwrites, with `None`) every channel.
pub fn color_target(
    format: wgpu::TextureFormat,
    blend: Option<wgpu::BlendState>,
) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState {
        format,
        blend,
        write_mask: wgpu::ColorWrites::ALL,
    })
}

/// A WGSL module from source text (its label names it in validation errors).
pub fn wgsl_module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

/// A compute pipeline running `entry` of `shader`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module: shader,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}
