//! The light maps of a batch (Ren 2010 §5): each light's convolution optical depth map (DODM,
//! one array layer per light slot) and its summed-area tables, at the full resolution or the
//! κ-simplified one, and the pass that draws them.

use super::frame_resources::FrameResources;
use super::light_kinds::{LightBatch, LightKinds, MapSize};
use super::stats::Timings;
use super::{EnvRenderError, EnvRenderOptions};
use crate::camera::LightFraming;
use crate::env_light::{EnvLight, shadow_groups};
use crate::gpu::GpuContext;
use crate::gpu::limits::{GpuLimits, LimitError};
use crate::passes::convolution_depth::{ConvolutionDepthPass, DodmBatch};
use crate::passes::head::{HeadDepthMaps, HeadPass};
use crate::passes::summed_area::{SummedAreaPass, SummedAreaTables};

/// A DODM batch (one array layer per light slot) against the adapter's limits; the image is
/// checked first, the SAT, the occupancy map and the sums when created.
fn check_light_map_limits(gpu: &GpuContext, resolution: u32, slots: u32) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    limits.check_texture_2d("DODM", resolution, resolution, |max| {
        format!("use a DODM resolution of at most {max}")
    })?;
    limits.check_texture_layers("DODM light batch", slots, |max| {
        format!("use a light batch size of at most {max}")
    })
}

/// Texels across the light maps bound, unread, by SRBF batches that read the visibility volume.
pub(super) const PLACEHOLDER_MAP_RESOLUTION: u32 = 8;

/// One resolution's light maps: the batch's DODM and its summed-area tables.
pub(super) struct LightMaps {
    pub(super) dodm: DodmBatch,
    pub(super) sat: SummedAreaTables,
    /// The head's depth from each slot's light, where the frame has a head.
    pub(super) head: Option<HeadDepthMaps>,
}

impl LightMaps {
    pub(super) fn new(
        gpu: &GpuContext,
        resolution: u32,
        slots: u32,
        first_layer: f32,
    ) -> Result<Self, EnvRenderError> {
        check_light_map_limits(gpu, resolution, slots)?;
        Ok(Self {
            sat: SummedAreaTables::new(gpu, resolution, slots)?,
            dodm: DodmBatch::new(gpu, resolution, slots, first_layer),
            head: None,
        })
    }

    /// A frame's full-resolution maps and its simplified ones (each None where no batch draws
    /// them), with as many slots as the most maps one batch of their kinds holds.
    fn full_and_simplified(
        gpu: &GpuContext,
        options: &EnvRenderOptions,
        kinds: &LightKinds,
        first_layer: f32,
    ) -> Result<(Option<Self>, Option<Self>), EnvRenderError> {
        if options.shadowed && options.lobe_visibility.volume().is_some() && kinds.has_srbf() {
            // SRBF lobes read the visibility volume: only the compact sources draw maps, and
            // SRBF batches bind a small placeholder that nothing reads.
            let sources = LightKinds {
                srbf_every_strand: Vec::new(),
                srbf: Vec::new(),
                directional: kinds.directional.clone(),
                directional_thinned: kinds.directional_thinned.clone(),
            };
            let placeholder = || Self::new(gpu, PLACEHOLDER_MAP_RESOLUTION, 1, first_layer);
            if !sources.has_directional() {
                return Ok((Some(placeholder()?), None));
            }
            let (full, simplified) =
                Self::full_and_simplified(gpu, options, &sources, first_layer)?;
            let full = match full {
                Some(maps) => maps,
                None => placeholder()?,
            };
            return Ok((Some(full), simplified));
        }
        let dodm = &options.dodm;
        let slots = |lights: &[&Vec<EnvLight>]| {
            let most = lights
                .iter()
                .map(|k| shadow_groups(k).len())
                .max()
                .unwrap_or(0);
            (dodm.batch_size as usize).min(most) as u32
        };
        let simplified_resolution = dodm.simplified_resolution(options.kappa);
        let full_kinds = [&kinds.srbf_every_strand, &kinds.directional];
        let thinned = kinds.thinned();
        if !kinds.has_thinned() || simplified_resolution == dodm.resolution {
            let full = match slots(&[full_kinds[0], full_kinds[1], thinned[0], thinned[1]]) {
                0 => None,
                all => Some(Self::new(gpu, dodm.resolution, all, first_layer)?),
            };
            return Ok((full, None));
        }
        let full = match slots(&full_kinds) {
            0 => None,
            n => Some(Self::new(gpu, dodm.resolution, n, first_layer)?),
        };
        let simplified = Self::new(gpu, simplified_resolution, slots(&thinned), first_layer)?;
        Ok((full, Some(simplified)))
    }

    /// GPU memory per resource, each name after `prefix`.
    pub(super) fn memory(&self, prefix: &str) -> Vec<(String, u64)> {
        let named = |(name, bytes): (String, u64)| (format!("{prefix}{name}"), bytes);
        let mut memory: Vec<_> = self.dodm.memory().into_iter().map(named).collect();
        memory.extend(self.sat.memory().into_iter().map(named));
        if let Some(head) = &self.head {
            memory.push(named(("head light depth".into(), head.memory())));
        }
        memory
    }
}

/// A frame's light maps, one set per [`MapSize`] its batches draw (None where none does), each
/// with as many slots as the most maps one of those batches holds.
pub(super) struct FrameLightMaps {
    /// Every-strand SRBFs' and directional lights' at the DODM resolution (and the simplified
    /// SRBFs' where theirs is the same).
    full: Option<LightMaps>,
    /// κ-simplified SRBFs' at [`DodmSettings::simplified_resolution`](crate::passes::convolution_depth::DodmSettings::simplified_resolution).
    simplified: Option<LightMaps>,
    /// Dominant compact sources' at [`DodmSettings::fine_resolution`](crate::passes::convolution_depth::DodmSettings::fine_resolution).
    fine: Option<LightMaps>,
}

impl FrameLightMaps {
    pub(super) fn for_frame(
        gpu: &GpuContext,
        options: &EnvRenderOptions,
        kinds: &LightKinds,
        first_layer: f32,
    ) -> Result<Self, EnvRenderError> {
        let (fine, directional): (Vec<EnvLight>, _) =
            (kinds.directional.iter()).partition(|l| l.has_fine_map());
        let fine = match shadow_groups(&fine)
            .len()
            .min(options.dodm.batch_size as usize)
        {
            0 => None,
            slots => Some(LightMaps::new(
                gpu,
                options.dodm.fine_resolution(),
                slots as u32,
                first_layer,
            )?),
        };
        let rest = LightKinds {
            srbf_every_strand: kinds.srbf_every_strand.clone(),
            srbf: kinds.srbf.clone(),
            directional,
            directional_thinned: kinds.directional_thinned.clone(),
        };
        let (full, simplified) = LightMaps::full_and_simplified(gpu, options, &rest, first_layer)?;
        Ok(Self {
            full,
            simplified,
            fine,
        })
    }

    /// The maps a batch of `size` draws: the simplified ones are the full ones where the
    /// frame has none of their own (the same resolution).
    pub(super) fn get_mut(&mut self, size: MapSize) -> &mut LightMaps {
        let maps = match size {
            MapSize::Fine => self.fine.as_mut(),
            MapSize::Simplified if self.simplified.is_some() => self.simplified.as_mut(),
            MapSize::Simplified | MapSize::Full => self.full.as_mut(),
        };
        maps.expect("a frame holds the light maps of every batch it draws")
    }

    /// Every set of maps the frame holds.
    pub(super) fn each_mut(&mut self) -> impl Iterator<Item = &mut LightMaps> {
        [&mut self.full, &mut self.simplified, &mut self.fine]
            .into_iter()
            .flatten()
    }

    /// GPU memory per resource, named by the maps' size.
    pub(super) fn memory(&self) -> Vec<(String, u64)> {
        [
            (&self.full, ""),
            (&self.simplified, "simplified "),
            (&self.fine, "fine "),
        ]
        .into_iter()
        .filter_map(|(maps, prefix)| maps.as_ref().map(|m| m.memory(prefix)))
        .flatten()
        .collect()
    }
}

/// The light maps of a batch: the light pass into the DODM (with the head's depth from each
/// light), then the summed-area tables of its optical depths.
pub(super) struct LightMapsPass {
    depth: ConvolutionDepthPass,
    sat: SummedAreaPass,
}

impl LightMapsPass {
    pub(super) fn new(gpu: &GpuContext) -> Self {
        Self {
            depth: ConvolutionDepthPass::new(gpu),
            sat: SummedAreaPass::new(gpu),
        }
    }

    /// The batch's light maps: the light pass into the DODM, then its summed-area tables.
    pub(super) fn encode(
        &self,
        gpu: &GpuContext,
        frame: &mut FrameResources,
        batch: &LightBatch<'_>,
        options: &EnvRenderOptions,
        head_pass: &HeadPass,
        timings: &mut Timings,
    ) {
        let simplified = batch.is_simplified();
        let directions: Vec<_> = batch.groups.iter().map(|g| g.direction).collect();
        let windows = match simplified {
            true => frame.next_windows(directions.len(), options.kappa),
            false => vec![vec![0..frame.view.geometry.segment_count]; directions.len()],
        };
        // A simplified map draws 1/κ-times the optical depth of each drawn fiber, enlarged to
        // the same world width at whatever resolution its maps have.
        let (tau_scale, enlargement) = match simplified {
            true => (
                1.0 / options.kappa,
                options.dodm.simplified_enlargement(options.kappa),
            ),
            false => (1.0, 1.0),
        };
        let FrameResources {
            view,
            footprint,
            maps,
            ..
        } = frame;
        let (geometry, head) = match simplified {
            true => (&view.light_geometry, &view.head),
            false => (&view.geometry, &view.head),
        };
        let maps = maps.get_mut(batch.map_size());
        let framing = match batch.has_sharp_shadows() {
            true => LightFraming::Fitted(footprint),
            false => LightFraming::Sphere(footprint.bounds),
        };
        timings.time(gpu, "light pass", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.depth.encode_windows(
                gpu,
                &mut encoder,
                geometry,
                &directions,
                &windows,
                framing,
                [tau_scale, enlargement],
                &mut maps.dodm,
            );
            if let (Some(head), Some(head_maps)) = (head.as_ref(), maps.head.as_ref()) {
                head_pass.encode_light_depths(
                    gpu,
                    &mut encoder,
                    head,
                    &maps.dodm.cameras,
                    head_maps,
                );
            }
            gpu.queue.submit([encoder.finish()]);
        });
        timings.time(gpu, "summed-area tables", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.sat
                .encode(gpu, &mut encoder, &maps.dodm.optical_depth, &maps.sat);
            gpu.queue.submit([encoder.finish()]);
        });
    }
}
