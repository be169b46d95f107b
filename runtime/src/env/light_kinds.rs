//! A frame's lights sorted into kinds and cut into batches: each batch is lights of one kind,
//! drawn into one set of light maps and shaded in one view pass.

use super::table_binding::TableBinding;
use crate::env_light::{EnvLight, ShadowGroup, shadow_groups};

/// A frame's lights split by kind, each batched apart: SRBFs and directional lights (each with
/// its own table), each drawing every strand into their maps or κ of them (one light-pass
/// geometry and one map size per batch). κ-thinned SRBFs are ranked by power, strongest first:
/// a thinned light's strand subset follows its place among them
/// ([`FrameResources::next_windows`](super::frame_resources::FrameResources::next_windows)), so the frame must not depend on the order its caller
/// lists the lobes in (`compare` lists them in fit order, `bench` by power).
pub(super) struct LightKinds {
    pub(super) srbf_every_strand: Vec<EnvLight>,
    pub(super) srbf: Vec<EnvLight>,
    pub(super) directional: Vec<EnvLight>,
    pub(super) directional_thinned: Vec<EnvLight>,
}

impl LightKinds {
    pub(super) fn of(lights: &[EnvLight]) -> Self {
        let (srbf, directional): (Vec<EnvLight>, _) =
            lights.iter().partition(|l| l.lambda.is_some());
        let (srbf_every_strand, mut srbf): (_, Vec<EnvLight>) =
            srbf.into_iter().partition(|l| l.every_strand);
        // Stable, so lights of equal power keep the caller's order.
        srbf.sort_by(|a, b| b.luminous_power().total_cmp(&a.luminous_power()));
        let (directional, directional_thinned) =
            directional.into_iter().partition(|l| l.every_strand);
        Self {
            srbf_every_strand,
            srbf,
            directional,
            directional_thinned,
        }
    }

    pub(super) fn has_srbf(&self) -> bool {
        !(self.srbf.is_empty() && self.srbf_every_strand.is_empty())
    }

    pub(super) fn has_directional(&self) -> bool {
        !(self.directional.is_empty() && self.directional_thinned.is_empty())
    }

    /// Whether any light is a compact source, whose maps are fitted to the hair
    /// ([`LightFraming::Fitted`](crate::camera::LightFraming::Fitted)).
    pub(super) fn has_sharp_shadows(&self) -> bool {
        self.compact_sources() > 0
    }

    /// How many lights are compact sources.
    pub(super) fn compact_sources(&self) -> usize {
        (self.directional.iter())
            .chain(&self.directional_thinned)
            .filter(|l| l.has_sharp_shadow())
            .count()
    }

    /// The kinds whose maps κ thins.
    pub(super) fn thinned(&self) -> [&Vec<EnvLight>; 2] {
        [&self.srbf, &self.directional_thinned]
    }

    pub(super) fn has_thinned(&self) -> bool {
        self.thinned().iter().any(|k| !k.is_empty())
    }
}

/// One batch: lights of one kind (at most the batch size of shadow groups) and their kind's
/// tables.
pub(super) struct LightBatch<'a> {
    pub(super) groups: &'a [ShadowGroup<'a>],
    pub(super) tables: &'a TableBinding,
}

impl LightKinds {
    /// Calls `render` with each batch of the frame, kind by kind (SRBFs drawing every strand,
    /// thinned SRBFs, directional lights, thinned directional lights), each with its kind's
    /// tables (a kind without tables has no lights), at most `batch_size` shadow groups a batch
    /// (`compact_batch_size` of compact sources: what the layered view's memory for their
    /// visibility holds).
    pub(super) fn for_each_batch<E>(
        &self,
        [srbf_tables, directional_tables]: [Option<&TableBinding>; 2],
        [batch_size, compact_batch_size]: [u32; 2],
        mut render: impl FnMut(&LightBatch<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let kind_tables = [
            (&self.srbf_every_strand, srbf_tables),
            (&self.srbf, srbf_tables),
            (&self.directional, directional_tables),
            (&self.directional_thinned, directional_tables),
        ];
        for (kind_lights, tables) in kind_tables {
            let Some(tables) = tables else { continue };
            let groups = shadow_groups(kind_lights);
            // A batch is shaded in one view: compact sources and region lights apart; and it
            // draws one size of map: the dominant sources' fine maps apart.
            let sharp = |g: &ShadowGroup| g.lights[0].has_sharp_shadow();
            let fine = |g: &ShadowGroup| g.lights[0].has_fine_map();
            for run in groups.chunk_by(|a, b| sharp(a) == sharp(b) && fine(a) == fine(b)) {
                let size = if sharp(&run[0]) {
                    compact_batch_size
                } else {
                    batch_size
                };
                for groups in run.chunks(size.max(1) as usize) {
                    render(&LightBatch { groups, tables })?;
                }
            }
        }
        Ok(())
    }
}

impl LightBatch<'_> {
    /// A batch holds one kind of light: its first tells the kind.
    pub(super) fn first_light(&self) -> Option<&EnvLight> {
        self.groups.first().map(|g| &g.lights[0])
    }

    /// Whether this batch's lights are compact sources, whose shadows are sharp at fiber scale
    /// (a batch holds lights of one view: [`EnvLight::has_sharp_shadow`]).
    pub(super) fn has_sharp_shadows(&self) -> bool {
        self.first_light().is_some_and(EnvLight::has_sharp_shadow)
    }

    /// Whether stochastic simplification thins this batch's maps.
    pub(super) fn is_simplified(&self) -> bool {
        self.first_light().is_some_and(|l| l.is_simplified())
    }

    /// Which of the frame's light maps this batch draws.
    pub(super) fn map_size(&self) -> MapSize {
        match self.first_light() {
            Some(l) if l.has_fine_map() => MapSize::Fine,
            Some(l) if l.is_simplified() => MapSize::Simplified,
            _ => MapSize::Full,
        }
    }
}

/// The frame's three sizes of light map: each batch draws one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MapSize {
    /// The DODM resolution: every-strand SRBFs and directional lights.
    Full,
    /// κ-simplified SRBFs' ([`DodmSettings::simplified_resolution`](crate::passes::convolution_depth::DodmSettings::simplified_resolution)).
    Simplified,
    /// Dominant compact sources' ([`DodmSettings::fine_resolution`](crate::passes::convolution_depth::DodmSettings::fine_resolution)).
    Fine,
}
