//! The lights of an env-lit frame: the set its settings ask for ([`EnvLightSet`]: the SRBF fit,
//! the DOM reference's cube of lights, median cut), made in the map's own frame, placed in the
//! hair's world by the one [`EnvOrientation`], then chosen (the strongest lobes).

use crate::env_lighting::{EnvLightSet, EnvLighting, ReferenceLighting};
use crate::env_orientation::EnvOrientation;
use crate::env_scene::PreparedEnv;
use anyhow::Context;
use strandlight_precompute::compact_sources::SourceOptions;
use strandlight_precompute::env_lights::{
    LightSpec, fitted_reference_lights, median_cut_lights, median_cut_lights_with_sources,
    reference_lights_shaded, srbf_set_lights,
};
use strandlight_runtime::env_light::EnvLight;
use strandlight_tables::colour::luminance_f32;

/// The compact sources the reference and the baseline take out exactly: the reference's
/// discretization, not the method's, so any fit leaves them (and the cached references) as
/// they are.
pub fn reference_sources() -> SourceOptions {
    SourceOptions::default()
}

/// The lights of the frame of `env`, in the hair's world. A fit's lights come most powerful
/// first, `env.lobes` of its SRBFs (all when None) and every compact source; the other sets in
/// the order they are made (a reference's sub-texels listed map by map).
pub fn frame_lights(prepared: &PreparedEnv, env: &EnvLighting) -> anyhow::Result<Vec<EnvLight>> {
    let orientation = EnvOrientation::new(prepared.up, env.rotation_deg as f64);
    let lights = orientation.lights(&light_specs(prepared, env.light_set)?);
    Ok(match env.light_set {
        EnvLightSet::Fit => strongest_first(lights, env.lobes),
        _ => lights,
    })
}

/// The set's lights in the map's own frame.
fn light_specs(prepared: &PreparedEnv, set: EnvLightSet) -> anyhow::Result<Vec<LightSpec>> {
    let fit = &prepared.scene.fit;
    Ok(match set {
        EnvLightSet::Fit => srbf_set_lights(fit),
        EnvLightSet::Reference {
            face,
            shading_face,
            lighting: ReferenceLighting::Map,
        } => {
            let shading = shading_face.unwrap_or(face).max(face);
            reference_lights_shaded(&prepared.map()?.map, face, shading, &reference_sources())
                .with_context(|| format!("a reference shaded at {shading}² texels a face"))?
        }
        EnvLightSet::Reference {
            face,
            lighting: ReferenceLighting::Fit,
            ..
        } => {
            let map = &prepared.map()?.map;
            let fit = srbf_set_lights(fit);
            fitted_reference_lights(&fit, map.width(), map.height(), face)?
        }
        EnvLightSet::MedianCut {
            lights,
            exact_sources: false,
        } => median_cut_lights(&prepared.map()?.map, lights),
        EnvLightSet::MedianCut {
            lights,
            exact_sources: true,
        } => median_cut_lights_with_sources(&prepared.map()?.map, lights, &reference_sources()),
    })
}

/// `lights` most powerful first, with only the `lobes` most powerful SRBFs (all when None) and
/// every directional light.
pub fn strongest_first(mut lights: Vec<EnvLight>, lobes: Option<usize>) -> Vec<EnvLight> {
    lights.sort_by(|a, b| light_luminance(b).total_cmp(&light_luminance(a)));
    let mut srbf_kept = 0;
    lights.retain(|l| {
        let keep = l.lambda.is_none() || lobes.is_none_or(|n| srbf_kept < n);
        srbf_kept += usize::from(l.lambda.is_some() && keep);
        keep
    });
    lights
}

/// The luminance of a light's power (Rec. 709 weights).
pub fn light_luminance(light: &EnvLight) -> f32 {
    luminance_f32(light.power())
}
