//! Someone else's renderer: a small wgpu application with its own device, its own meshes (a
//! head and a floor), depth buffer and camera, that adds strandlight's hair with the runtime's
//! host API ([`HairRenderer`]). It renders headless and writes `host.png` and `host.exr`.
//!
//! ```text
//! cargo run --release -p strandlight-runtime --example host -- [--settings FRAME.json] [--out DIR]
//! ```
//!
//! Without `--settings` it draws the default scene: the procedural groom under the procedural
//! sun and sky (its tables are baked into `out/cache` on first use, as `render` does). A
//! point-lit settings file (`render lights`' sidecar) is drawn with the thesis techniques.
//! tests/host_embedding.rs runs [`run`] and checks the picture against `render replay`.

use anyhow::Context;
use glam::Vec3;
use std::path::{Path, PathBuf};
use strandlight_runtime::camera::Camera;
use strandlight_runtime::gpu::{GpuContext, read_texture_rgba, readbacks_so_far};
use strandlight_runtime::host::{HairRenderer, HairTargets};
use strandlight_scene::env_frame::{hair_frame, lights_call};
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::frame_render::{
    FramePart, env_frame, load_settings_hair, point_frame_inputs, point_lit_frame, prepare_point,
    settings_camera,
};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::steps::Steps;
use wgpu::util::DeviceExt;

/// The host's targets: HDR colour (the hair is linear radiance) and a depth buffer.
const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The host's own picture of one frame, and what the test checks it with.
pub struct HostFrame {
    pub size: [u32; 2],
    /// The host's meshes with the hair drawn into the same pass (linear RGBA).
    pub with_hair: Vec<[f32; 4]>,
    /// The host's meshes alone.
    pub host_only: Vec<[f32; 4]>,
    /// The host's triangles (world space) and the camera it projected them with.
    pub triangles: Vec<[Vec3; 3]>,
    pub camera: Camera,
    /// The hair's front depth (wgpu's 0..1; 1 where there is no hair).
    pub hair_depth: Vec<f32>,
}

/// The host: its device, its meshes and their pipeline.
struct Host {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    vertices: wgpu::Buffer,
    vertex_count: u32,
}

/// Milliseconds of whole frames (new frame, every batch, the host's pass), each waited for
/// after submission: the frame on the GPU alone, and the same with the frame's sums read back.
pub struct FrameTimes {
    pub on_gpu: Vec<f64>,
    pub with_readback: Vec<f64>,
    /// GPU→CPU copies the runtime made during the frames on the GPU (none is needed).
    pub readbacks_on_gpu: u64,
}

/// Renders `settings`' hair into the host's scene (tables cached under `cache`), and times
/// `timed_frames` more frames each way. Env-lit settings are drawn batch by batch, point-lit
/// ones (the thesis techniques) whole.
pub fn run(
    settings: &FrameSettings,
    cache: &Path,
    timed_frames: usize,
) -> anyhow::Result<(HostFrame, FrameTimes)> {
    // What the application had before it wanted hair: its device, meshes and camera.
    let hair = load_settings_hair(settings)?;
    let camera = settings_camera(settings, &hair.model)?;
    let triangles = head_and_floor(&hair.model.bounds());
    let host = Host::new(&triangles, camera.view_projection(settings.size))?;

    // The hair, on the host's device, into the host's pass.
    let gpu = GpuContext::from_device(host.device.clone(), host.queue.clone());
    let targets = HairTargets {
        color: COLOR,
        depth: Some(DEPTH),
        sample_count: 1,
    };
    let hair_renderer = HairRenderer::new(&host.device, &host.queue, targets);
    let scene = HostScene {
        host,
        size: settings.size,
        camera,
        triangles,
    };
    match &settings.lighting {
        Lighting::Environment(_) => {
            let prepared = prepare_env(
                settings,
                &hair.model,
                cache,
                AlsoServe::default(),
                &mut Steps::new(true),
                &mut |_| {},
            )?;
            let frame = env_frame(settings, &hair.model, &prepared, FramePart::Whole, false)?;
            let call = lights_call(&frame, &gpu)?;
            let hair_frame = hair_frame(&frame, &call);
            scene.draw_hair(hair_renderer, timed_frames, |hair_renderer| {
                hair_renderer.prepare(&hair_frame)?;
                while !hair_renderer.encode_next_batch(&hair_frame)?.converged() {}
                Ok(())
            })
        }
        Lighting::Lights(point) => {
            let prepared = prepare_point(settings, point)?;
            let inputs = point_frame_inputs(settings, point, &hair.model, settings.size)?;
            let frame = point_lit_frame(&hair.model, &prepared, &inputs);
            scene.draw_hair(hair_renderer, timed_frames, |hair_renderer| {
                Ok(hair_renderer.draw_point_lit(&frame)?)
            })
        }
    }
}

/// The host's scene before the hair: its meshes and the camera it projects them with.
struct HostScene {
    host: Host,
    size: [u32; 2],
    camera: Camera,
    triangles: Vec<[Vec3; 3]>,
}

impl HostScene {
    /// Adds the hair `new_frame` draws (a new frame, on the host's device) to the host's pass:
    /// times `timed_frames` frames each way, then draws the checked picture.
    fn draw_hair(
        self,
        mut hair_renderer: HairRenderer,
        timed_frames: usize,
        mut new_frame: impl FnMut(&mut HairRenderer) -> anyhow::Result<()>,
    ) -> anyhow::Result<(HostFrame, FrameTimes)> {
        let Self {
            host,
            size,
            camera,
            triangles,
        } = self;
        new_frame(&mut hair_renderer)?;
        let mut times = FrameTimes {
            on_gpu: Vec::new(),
            with_readback: Vec::new(),
            readbacks_on_gpu: 0,
        };
        for readback in [false, true].repeat(timed_frames) {
            let readbacks_before = readbacks_so_far();
            let start = std::time::Instant::now();
            new_frame(&mut hair_renderer)?;
            host.draw_pass(size, Some(&hair_renderer));
            match readback {
                true => drop(hair_renderer.read_pixels()?),
                false => {
                    times.readbacks_on_gpu += readbacks_so_far() - readbacks_before;
                    drop(host.device.poll(wgpu::PollType::wait_indefinitely()))
                }
            }
            let ms = start.elapsed().as_secs_f64() * 1e3;
            match readback {
                true => times.with_readback.push(ms),
                false => times.on_gpu.push(ms),
            }
        }
        // The picture is drawn after the timed frames: each started again on the same sums.
        let with_hair = host.draw(size, Some(&hair_renderer))?;
        let host_only = host.draw(size, None)?;
        let frame = HostFrame {
            size,
            with_hair,
            host_only,
            triangles,
            camera,
            hair_depth: hair_renderer.read_front_depth()?,
        };
        Ok((frame, times))
    }
}

impl Host {
    fn new(triangles: &[[Vec3; 3]], view_projection: glam::Mat4) -> anyhow::Result<Self> {
        let (device, queue) = pollster::block_on(host_device())?;
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("host mesh"),
            source: wgpu::ShaderSource::Wgsl(HOST_SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host camera"),
            contents: bytemuck::bytes_of(&view_projection.to_cols_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host camera"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        let pipeline = mesh_pipeline(&device, &shader, &layout);
        let vertices: Vec<[f32; 6]> = triangles
            .iter()
            .enumerate()
            .flat_map(|(i, t)| {
                let colour = if i < 2 { FLOOR } else { HEAD };
                t.map(|p| [p.x, p.y, p.z, colour[0], colour[1], colour[2]])
            })
            .collect();
        let vertex_count = vertices.len() as u32;
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host mesh"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Ok(Self {
            device,
            queue,
            pipeline,
            group,
            vertices,
            vertex_count,
        })
    }

    /// [`Self::draw_pass`], read back once to write it.
    fn draw(&self, size: [u32; 2], hair: Option<&HairRenderer>) -> anyhow::Result<Vec<[f32; 4]>> {
        let colour = self.draw_pass(size, hair);
        let gpu = GpuContext::from_device(self.device.clone(), self.queue.clone());
        Ok(read_texture_rgba(&gpu, &colour)?)
    }

    /// One frame: the host's meshes, then (when given) the hair, in one render pass, submitted.
    fn draw_pass(&self, [w, h]: [u32; 2], hair: Option<&HairRenderer>) -> wgpu::Texture {
        let target = |format, usage| {
            self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("host target"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = target(
            COLOR,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = target(DEPTH, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let (colour_view, depth_view) = (
            colour.create_view(&Default::default()),
            depth.create_view(&Default::default()),
        );
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.set_vertex_buffer(0, self.vertices.slice(..));
            pass.draw(0..self.vertex_count, 0..1);
            if let Some(hair) = hair {
                hair.render(&mut pass);
            }
        }
        self.queue.submit([encoder.finish()]);
        colour
    }
}

/// The host's own device, as any wgpu application opens one: the runtime asks it for the
/// features it can use (f32 targets and filtering) where the adapter has them.
async fn host_device() -> anyhow::Result<(wgpu::Device, wgpu::Queue)> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = instance
        .request_adapter(&Default::default())
        .await
        .context("no GPU adapter (on a machine without a GPU install lavapipe)")?;
    Ok(adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("host"),
            required_features: GpuContext::wanted_features(adapter.features()),
            required_limits: adapter.limits(),
            ..Default::default()
        })
        .await?)
}

fn mesh_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    layout: &wgpu::BindGroupLayout,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host mesh"),
        layout: Some(
            &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("host mesh"),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            }),
        ),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 24,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
            })],
        },
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR.into())],
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

/// Flat colours, so the host's own pixels are known exactly.
const FLOOR: [f32; 3] = [0.18, 0.18, 0.2];
const HEAD: [f32; 3] = [0.6, 0.3, 0.2];

const HOST_SHADER: &str = "
@group(0) @binding(0) var<uniform> view_projection: mat4x4<f32>;
struct Out { @builtin(position) at: vec4<f32>, @location(0) colour: vec3<f32> };
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) colour: vec3<f32>) -> Out {
    return Out(view_projection * vec4<f32>(p, 1.0), colour);
}
@fragment fn fs(v: Out) -> @location(0) vec4<f32> { return vec4<f32>(v.colour, 1.0); }
";

/// A floor under the hair (two triangles) and a ball in front of its lower left that hides part
/// of it: the host's meshes, in world space.
fn head_and_floor(bounds: &strandlight_runtime::hair::Aabb) -> Vec<[Vec3; 3]> {
    let (min, max) = (bounds.min, bounds.max);
    let centre = 0.5 * (min + max);
    let size = (max - min).length();
    let y = min.y;
    let (a, b) = (centre.x - size, centre.x + size);
    let (c, d) = (centre.z - size, centre.z + size);
    let mut triangles = vec![
        [Vec3::new(a, y, c), Vec3::new(b, y, c), Vec3::new(b, y, d)],
        [Vec3::new(a, y, c), Vec3::new(b, y, d), Vec3::new(a, y, d)],
    ];
    let ball = centre + Vec3::new(-0.12 * size, -0.1 * size, 0.35 * size);
    triangles.extend(sphere(ball, 0.18 * size, 24, 16));
    triangles
}

/// A UV sphere's triangles.
fn sphere(centre: Vec3, radius: f32, around: u32, down: u32) -> Vec<[Vec3; 3]> {
    let point = |i: u32, j: u32| {
        let phi = std::f32::consts::TAU * i as f32 / around as f32;
        let theta = std::f32::consts::PI * j as f32 / down as f32;
        centre
            + radius
                * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                )
    };
    (0..around)
        .flat_map(|i| (0..down).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (p00, p10, p01, p11) = (
                point(i, j),
                point(i + 1, j),
                point(i, j + 1),
                point(i + 1, j + 1),
            );
            [[p00, p10, p11], [p00, p11, p01]]
        })
        .collect()
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut settings_file, mut out, mut timed) = (None, PathBuf::from("out/host"), 0);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--settings" => {
                settings_file = Some(PathBuf::from(args.next().context("--settings FILE")?))
            }
            "--out" => out = PathBuf::from(args.next().context("--out DIR")?),
            "--time" => timed = args.next().context("--time FRAMES")?.parse()?,
            other => anyhow::bail!(
                "unknown argument {other:?} (use --settings FILE, --out DIR, --time FRAMES)"
            ),
        }
    }
    let settings = match &settings_file {
        Some(file) => FrameSettings::read(file)?,
        None => FrameSettings::new(
            Lighting::Environment(EnvLighting::new("procedural:sun_and_sky")),
            [640, 480],
        ),
    };
    let (frame, times) = run(&settings, Path::new("out/cache"), timed)?;
    if timed > 0 {
        let median = |t: &[f64]| {
            let mut t = t.to_vec();
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        };
        let (gpu, read) = (median(&times.on_gpu), median(&times.with_readback));
        println!(
            "host frame {}x{}, median of {timed}: {gpu:.1} ms on the GPU, {read:.1} ms with the \
             frame read back ({:+.1}%)",
            frame.size[0],
            frame.size[1],
            100.0 * (read / gpu - 1.0)
        );
    }
    std::fs::create_dir_all(&out).with_context(|| format!("--out {}", out.display()))?;
    let [w, h] = frame.size;
    let exr = out.join("host.exr");
    strandlight_tables::image_out::write_exr(
        &exr,
        w,
        h,
        &frame.with_hair,
        "strandlight host example",
    )?;
    let png = out.join("host.png");
    strandlight_tables::image_out::write_png(
        &png,
        w,
        h,
        &frame.with_hair,
        "strandlight host example",
    )?;
    println!("wrote {} and {}", png.display(), exr.display());
    Ok(())
}
