//! The Bevy side: the groom as a line list with per-vertex tangents, drawn by a `Material`
//! whose fragment shader is strandlight's exported `strandlight_lut.wgsl` followed by the
//! SRBF single-scattering sum of `runtime/examples/ktx2_strand.rs`:
//!   L_o = Σ_j I(u·ξ_j, u·ω_o, cos(φ_ξj − φ_o), 1/λ_j) · L_j
//! with I the exported KTX2 convolution table, sampled by `strandlight_lut_3d` (the hardware's
//! trilinear filter and two slabs). Rendered headless into an rgba32float image (through
//! Bevy's HDR rgba16float view target, no tonemapping, no MSAA) and read back.

use crate::scene::{Hair, Lobe, Settings};
use anyhow::{Context, bail};
use bevy::app::{AppExit, ScheduleRunnerPlugin};
use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::camera::{Hdr, RenderTarget};
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler, ImageSamplerDescriptor};
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::{
    AsBindGroup, Extent3d, ShaderType, TextureDimension, TextureFormat, TextureUsages,
};
use bevy::render::view::Msaa;
use bevy::shader::ShaderRef;
use bevy::window::ExitCondition;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The most SRBF lobes the material's uniform holds (`strandlight fit --max-lobes` defaults to 64).
pub const MAX_LOBES: usize = 64;

const SHADER: Handle<Shader> = uuid_handle!("5c0b3f36-2d55-4d8e-9f0a-6d1c2a1e7b41");

/// A deliberate error, to show that the comparison catches one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeliberateError {
    None,
    /// Every light mirrored left–right (world x negated): a handedness slip in placing the map.
    Mirror,
    /// The LUT's first two axes swapped: u·ω_o where u·ξ belongs and back.
    SwapAxes,
}

impl DeliberateError {
    pub fn parse(s: &str) -> anyhow::Result<Self> {
        Ok(match s {
            "none" => Self::None,
            "mirror" => Self::Mirror,
            "swap-axes" => Self::SwapAxes,
            _ => bail!("--deliberate-error {s}: mirror, swap-axes or none"),
        })
    }
}

/// strandlight_lut.wgsl's `StrandLutAxis` (32 bytes; the sidecar's `wgsl.uniform`).
#[derive(Clone, Copy, Debug, Default, ShaderType)]
pub struct StrandLutAxis {
    pub min: f32,
    pub inv_range: f32,
    pub last_index: f32,
    pub inv_exponent: f32,
    pub warp: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

#[derive(Clone, Copy, Debug, Default, ShaderType)]
pub struct StrandLut {
    pub axes: [StrandLutAxis; 4],
}

/// The lights: per lobe toward its centre (xyz) and 1/λ (w), and its amplitude (rgb).
#[derive(Clone, Copy, Debug, ShaderType)]
pub struct Lights {
    /// x: the lobe count; y: 1 swaps the LUT's first two coordinates (a deliberate error).
    pub counts: UVec4,
    pub direction: [Vec4; MAX_LOBES],
    pub rgb: [Vec4; MAX_LOBES],
}

#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
pub struct StrandMaterial {
    #[texture(0, dimension = "3d")]
    #[sampler(1)]
    pub lut_texture: Handle<Image>,
    #[uniform(2)]
    pub lut: StrandLut,
    #[uniform(3)]
    pub lights: Lights,
}

impl Material for StrandMaterial {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }
}

/// The material's fragment stage, after strandlight_lut.wgsl.
const FRAGMENT: &str = r#"
#import bevy_pbr::forward_io::VertexOutput
#import bevy_pbr::mesh_view_bindings::view

struct Lights {
    counts: vec4<u32>,
    direction: array<vec4<f32>, 64>,
    rgb: array<vec4<f32>, 64>,
};

@group(#{MATERIAL_BIND_GROUP}) @binding(0) var lut_texture: texture_3d<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(1) var lut_sampler: sampler;
@group(#{MATERIAL_BIND_GROUP}) @binding(2) var<uniform> lut: StrandLut;
@group(#{MATERIAL_BIND_GROUP}) @binding(3) var<uniform> lights: Lights;

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    let u = normalize(in.world_tangent.xyz);
    let e = normalize(view.world_position - in.world_position.xyz);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < lights.counts.x; j++) {
        let xi = normalize(lights.direction[j].xyz);
        let s_xi = clamp(dot(u, xi), -1.0, 1.0);
        let s_o = clamp(dot(u, e), -1.0, 1.0);
        let xp = xi - s_xi * u;
        let ep = e - s_o * u;
        let norms = dot(xp, xp) * dot(ep, ep);
        var cos_dphi = 1.0;
        if (norms > 1e-20) { cos_dphi = clamp(dot(xp, ep) * inverseSqrt(norms), -1.0, 1.0); }
        var coords = vec4<f32>(s_xi, s_o, cos_dphi, lights.direction[j].w);
        if (lights.counts.y == 1u) { coords = vec4<f32>(s_o, s_xi, cos_dphi, lights.direction[j].w); }
        sum += strandlight_lut_3d(lut_texture, lut_sampler, lut, coords).rgb * lights.rgb[j].rgb;
    }
    return vec4<f32>(sum, 1.0);
}
"#;

/// An exported LUT as an engine loads it: `<dir>/<name>.ktx2` (read with the `ktx2` crate) and
/// the `StrandLut` uniform from `<dir>/<name>.json`.
pub fn load_lut(dir: &Path, name: &str) -> anyhow::Result<(Image, StrandLut)> {
    let ktx_path = dir.join(format!("{name}.ktx2"));
    let bytes = std::fs::read(&ktx_path).with_context(|| ktx_path.display().to_string())?;
    let reader = ktx2::Reader::new(bytes.as_slice())
        .map_err(|e| anyhow::anyhow!("{}: {e:?}", ktx_path.display()))?;
    let header = reader.header();
    let format = match header.format {
        Some(ktx2::Format::R16G16B16A16_SFLOAT) => TextureFormat::Rgba16Float,
        other => bail!(
            "{}: format {other:?}; this example samples rgba16float tables (filterable everywhere): export with --export-format half",
            ktx_path.display()
        ),
    };
    if header.pixel_depth == 0 {
        bail!(
            "{}: a 2D texture; a 4D table is a 3D texture",
            ktx_path.display()
        );
    }
    let texels = reader
        .levels()
        .next()
        .map(|l| l.data.to_vec())
        .context("no level")?;
    let size = Extent3d {
        width: header.pixel_width,
        height: header.pixel_height,
        depth_or_array_layers: header.pixel_depth,
    };
    let mut image = Image::new(
        size,
        TextureDimension::D3,
        texels,
        format,
        RenderAssetUsages::RENDER_WORLD,
    );
    // The sidecar's sampler: linear min/mag, clamp to edge, one level.
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        label: Some("strandlight lut".into()),
        address_mode_u: ImageAddressMode::ClampToEdge,
        address_mode_v: ImageAddressMode::ClampToEdge,
        address_mode_w: ImageAddressMode::ClampToEdge,
        mag_filter: ImageFilterMode::Linear,
        min_filter: ImageFilterMode::Linear,
        mipmap_filter: ImageFilterMode::Nearest,
        ..default()
    });

    let json_path = dir.join(format!("{name}.json"));
    let text =
        std::fs::read_to_string(&json_path).with_context(|| json_path.display().to_string())?;
    let sidecar: serde_json::Value = serde_json::from_str(&text)?;
    let axes = sidecar["wgsl"]["uniform"]
        .as_array()
        .filter(|a| a.len() == 4)
        .with_context(|| format!("{}: no wgsl.uniform of four axes", json_path.display()))?;
    let mut lut = StrandLut::default();
    for (k, a) in axes.iter().enumerate() {
        let f = |key: &str| a[key].as_f64().map(|v| v as f32).context("axis value");
        lut.axes[k] = StrandLutAxis {
            min: f("min")?,
            inv_range: f("inv_range")?,
            last_index: f("last_index")?,
            inv_exponent: f("inv_exponent")?,
            warp: a["warp"].as_u64().context("warp")? as u32,
            ..default()
        };
    }
    Ok((image, lut))
}

/// The groom as a line list: each segment's two points, each point with its tangent.
pub fn hair_mesh(hair: &Hair) -> Mesh {
    let tangents = hair.tangents();
    let positions: Vec<[f32; 3]> = hair.points.iter().map(|p| p.to_array()).collect();
    let tangents: Vec<[f32; 4]> = tangents.iter().map(|t| t.extend(1.0).to_array()).collect();
    let mut indices = Vec::new();
    for w in hair.offsets.windows(2) {
        for i in w[0]..w[1] - 1 {
            indices.extend([i as u32, i as u32 + 1]);
        }
    }
    Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::RENDER_WORLD)
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
        .with_inserted_attribute(Mesh::ATTRIBUTE_TANGENT, tangents)
        .with_inserted_indices(Indices::U32(indices))
}

/// What the Bevy app is given.
#[derive(Resource, Clone)]
struct Job {
    settings: Arc<Settings>,
    hair: Arc<Hair>,
    lobes: Vec<Lobe>,
    lut_dir: PathBuf,
    lut_name: String,
    wgsl: String,
    error: DeliberateError,
    /// The image read back: RGBA f32, row by row from the top.
    result: Arc<Mutex<Option<Vec<f32>>>>,
}

/// Frames seen since the start, and the last read-back's hair pixel count.
#[derive(Resource, Default)]
struct Progress {
    frames: u32,
    last_count: Option<usize>,
    stable: u32,
}

/// Renders the frame of `settings` with Bevy and returns its RGBA f32 pixels (top row first).
pub fn render(
    settings: Settings,
    hair: Hair,
    lobes: Vec<Lobe>,
    lut_dir: &Path,
    lut_name: &str,
    error: DeliberateError,
) -> anyhow::Result<Vec<f32>> {
    if lobes.len() > MAX_LOBES {
        bail!("{} lobes; the material holds {MAX_LOBES}", lobes.len());
    }
    let wgsl_path = lut_dir.join("strandlight_lut.wgsl");
    let wgsl =
        std::fs::read_to_string(&wgsl_path).with_context(|| wgsl_path.display().to_string())?;
    let result = Arc::new(Mutex::new(None));
    let job = Job {
        settings: Arc::new(settings),
        hair: Arc::new(hair),
        lobes,
        lut_dir: lut_dir.to_path_buf(),
        lut_name: lut_name.to_string(),
        wgsl,
        error,
        result: result.clone(),
    };
    let exit = App::new()
        .insert_resource(job)
        .init_resource::<Progress>()
        .add_plugins((
            DefaultPlugins.set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            }),
            ScheduleRunnerPlugin::run_loop(Duration::ZERO),
            MaterialPlugin::<StrandMaterial>::default(),
        ))
        .add_systems(Startup, setup)
        .add_systems(Update, give_up)
        .run();
    if let AppExit::Error(code) = exit {
        bail!("the Bevy app exited with {code}");
    }
    let pixels = result.lock().unwrap().take();
    pixels.context("Bevy drew no hair within the frame limit (did the pipeline compile?)")
}

fn setup(
    mut commands: Commands,
    job: Res<Job>,
    mut shaders: ResMut<Assets<Shader>>,
    mut images: ResMut<Assets<Image>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StrandMaterial>>,
) {
    // The exported sampling functions, pasted before the material's own code.
    let source = format!("{}\n{}", job.wgsl, FRAGMENT);
    shaders
        .insert(
            &SHADER,
            Shader::from_wgsl(source, "strandlight_bevy_material.wgsl"),
        )
        .expect("shader handle");

    let (lut_image, lut) = load_lut(&job.lut_dir, &job.lut_name).unwrap_or_else(|e| {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    });
    let mut lights = Lights {
        counts: UVec4::new(job.lobes.len() as u32, 0, 0, 0),
        direction: [Vec4::ZERO; MAX_LOBES],
        rgb: [Vec4::ZERO; MAX_LOBES],
    };
    for (j, l) in job.lobes.iter().enumerate() {
        let mut d = l.direction;
        if job.error == DeliberateError::Mirror {
            d.x = -d.x;
        }
        lights.direction[j] = d.extend(l.inv_lambda);
        lights.rgb[j] = Vec3::from(l.rgb).extend(0.0);
    }
    if job.error == DeliberateError::SwapAxes {
        lights.counts.y = 1;
    }
    let material = materials.add(StrandMaterial {
        lut_texture: images.add(lut_image),
        lut,
        lights,
    });
    commands.spawn((
        Mesh3d(meshes.add(hair_mesh(&job.hair))),
        MeshMaterial3d(material),
        Transform::IDENTITY,
        bevy::camera::visibility::NoFrustumCulling,
    ));

    let [width, height] = job.settings.size;
    let mut target = Image::new_target_texture(width, height, TextureFormat::Rgba32Float, None);
    target.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    let target = images.add(target);
    let c = job.settings.camera;
    commands.spawn((
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(Color::NONE),
            ..default()
        },
        RenderTarget::Image(target.clone().into()),
        Projection::Perspective(PerspectiveProjection {
            fov: c.fov_y_deg.to_radians(),
            aspect_ratio: width as f32 / height as f32,
            near: c.near,
            far: c.far,
            ..default()
        }),
        Hdr,
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_translation(c.eye).looking_at(c.target, c.up),
    ));

    let (row_floats, rows) = (4 * width as usize, height as usize);
    commands.spawn(Readback::texture(target)).observe(
        move |event: On<ReadbackComplete>,
              job: Res<Job>,
              mut progress: ResMut<Progress>,
              mut exit: MessageWriter<AppExit>| {
            let data: &[u8] = &event.data;
            // Rows may be padded to 256 bytes.
            let row_bytes = data.len() / rows;
            let mut pixels = Vec::with_capacity(row_floats * rows);
            for r in 0..rows {
                let row = &data[r * row_bytes..r * row_bytes + 4 * row_floats];
                pixels.extend(
                    row.chunks_exact(4)
                        .map(|b| f32::from_le_bytes(b.try_into().unwrap())),
                );
            }
            let count = pixels.chunks_exact(4).filter(|p| p[3] > 0.5).count();
            // Pipelines compile asynchronously: wait until the hair is drawn and the same
            // three read-backs running.
            if count > 0 && progress.last_count == Some(count) {
                progress.stable += 1;
            } else {
                progress.stable = 0;
            }
            progress.last_count = Some(count);
            if progress.stable >= 2 {
                *job.result.lock().unwrap() = Some(pixels);
                exit.write(AppExit::Success);
            }
        },
    );
}

fn give_up(mut progress: ResMut<Progress>, mut exit: MessageWriter<AppExit>) {
    progress.frames += 1;
    if progress.frames > 2000 {
        eprintln!("error: no stable frame after 2000 frames");
        exit.write(AppExit::error());
    }
}
