//! A scene's hair and image size as a user names them: a hair file (or the procedural groom when
//! none is given) and `WxH`.

use crate::point_shading::Shading;
use anyhow::{Context, bail};
use std::path::Path;
use strandlight_runtime::hair::{self, GroomParams, HairModel};

/// The hair file at `path` (format by extension, see [`hair::EXTENSIONS`]), or the procedural
/// groom, with a description. A scene file's description says what was read and how it was
/// converted (prims, units, up axis, values dropped), since a user cannot see that in the picture.
pub fn load_hair(path: Option<&Path>) -> anyhow::Result<(HairModel, String)> {
    match path {
        Some(path) => {
            let loaded = hair::load(path)?;
            let scene_file = matches!(
                loaded.report.format,
                hair::HairFormat::Usd | hair::HairFormat::Alembic
            );
            let source = if scene_file {
                format!("{} ({})", path.display(), loaded.report.info)
            } else {
                path.display().to_string()
            };
            Ok((loaded.model, source))
        }
        None => Ok((
            hair::generate_groom(&GroomParams::default())?,
            "procedural groom (default parameters)".to_string(),
        )),
    }
}

/// `WxH` (e.g. `656x861`) as two positive sides. Whether the GPU can hold that image is checked
/// where its textures are declared.
pub fn parse_size(text: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("--size {text:?}: expected WxH, e.g. 656x861"))?;
    let parse = |s: &str| -> anyhow::Result<u32> {
        let v: u32 = s
            .trim()
            .parse()
            .with_context(|| format!("--size {text:?}: {s:?} is not a whole number"))?;
        if v == 0 {
            bail!("--size {text:?}: sides must be at least 1 pixel");
        }
        Ok(v)
    };
    Ok((parse(w)?, parse(h)?))
}

/// `hair` as `shading` renders it: the Chiang fiber is the path tracer's, whose fibers are opaque
/// cylinders, so a file's transparency is dropped for it. The flag says whether it was dropped.
pub fn opaque_if_physical(shading: impl Into<Shading>, hair: HairModel) -> (HairModel, bool) {
    if hair.transparency().is_some() && shading.into().physical_fibers() {
        (hair.without_transparency(), true)
    } else {
        (hair, false)
    }
}

/// What marks a hair's cache identity where its fibers were made opaque.
pub const OPAQUE_FIBERS: &str = "+opaque fibers";

/// [`opaque_if_physical`], with the hash that identifies the hair in the caches (it says when
/// the transparency was dropped).
pub fn fibers_for(
    shading: impl Into<Shading>,
    hair: HairModel,
    sha256: String,
) -> (HairModel, String) {
    match opaque_if_physical(shading, hair) {
        (hair, true) => (hair, format!("{sha256}{OPAQUE_FIBERS}")),
        (hair, false) => (hair, sha256),
    }
}
