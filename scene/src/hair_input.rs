//! A scene's hair and image size as a user names them: a hair file or a procedural groom
//! (`procedural:NAME`; the default style when none is given) and `WxH`.

use crate::point_shading::Shading;
use anyhow::{Context, bail};
use std::path::Path;
use strandlight_runtime::hair::{self, GroomStyle, HairModel};

/// What names a procedural groom's style where a hair file could stand (as `procedural:NAME`
/// names a built-in environment map).
pub const PROCEDURAL_PREFIX: &str = "procedural:";

/// The groom style `path` names (`procedural:NAME`), or None for a file.
pub fn procedural_style(path: &Path) -> anyhow::Result<Option<GroomStyle>> {
    let Some(name) = path
        .to_str()
        .and_then(|p| p.strip_prefix(PROCEDURAL_PREFIX))
    else {
        return Ok(None);
    };
    match GroomStyle::named(name) {
        Some(style) => Ok(Some(style)),
        None => bail!(
            "--hair {}: no procedural groom called {name:?}; the styles are {}",
            path.display(),
            GroomStyle::ALL
                .map(|s| format!("{PROCEDURAL_PREFIX}{}", s.name()))
                .join(", ")
        ),
    }
}

/// The procedural groom of `style`, with its description.
fn procedural_groom(style: GroomStyle) -> anyhow::Result<(HairModel, String)> {
    Ok((
        hair::generate_groom(&style.params())?,
        format!("procedural groom ({PROCEDURAL_PREFIX}{})", style.name()),
    ))
}

/// The hair file at `path` (format by extension, see [`hair::EXTENSIONS`]) or procedural groom
/// it names (the default style when None), with a description. A scene file's description says
/// what was read and how it was converted (prims, units, up axis, values dropped), since a user
/// cannot see that in the picture.
pub fn load_hair(path: Option<&Path>) -> anyhow::Result<(HairModel, String)> {
    if let Some(style) = path.map(procedural_style).transpose()?.flatten() {
        return procedural_groom(style);
    }
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
        None => procedural_groom(GroomStyle::default()),
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

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_runtime::hair::generate_groom;

    #[test]
    fn procedural_names_a_style_and_a_wrong_name_lists_them() {
        let (curly, source) = load_hair(Some(Path::new("procedural:curly"))).unwrap();
        assert_eq!(curly, generate_groom(&GroomStyle::Curly.params()).unwrap());
        assert!(source.contains("procedural:curly"), "{source}");
        let (default, _) = load_hair(None).unwrap();
        assert_eq!(
            default,
            generate_groom(&GroomStyle::default().params()).unwrap()
        );
        // A file is not a style, whatever its name.
        assert_eq!(procedural_style(Path::new("curly.hair")).unwrap(), None);
        let error = load_hair(Some(Path::new("procedural:mohawk")))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("mohawk") && error.contains("procedural:wavy-bob"),
            "{error}"
        );
    }
}
