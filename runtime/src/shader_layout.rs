//! Test support: a struct the runtime uploads (`#[repr(C)]`, bytemuck) against the WGSL struct
//! that reads it, both laid out by their compilers: rustc's offsets (`offset_of!`) against
//! naga's layout of the composed shader. The two are written by hand side by side; a field
//! added, removed, reordered or resized on one side only moves an offset or the size.

use crate::shaders::{Wgsl, compose};
use wgpu::naga;

/// A Rust struct's size and the offsets of its fields, each under the name of the WGSL member
/// that must sit at the same offset.
pub(crate) struct RustLayout {
    pub(crate) name: &'static str,
    pub(crate) size: usize,
    pub(crate) fields: Vec<(&'static str, usize)>,
}

/// The [`RustLayout`] of `$ty`: each `field` meets the WGSL member of its name, or
/// `field => "member"` another.
macro_rules! rust_layout {
    ($ty:ty { $($field:ident $(=> $member:literal)?),* $(,)? }) => {
        $crate::shader_layout::RustLayout {
            name: stringify!($ty),
            size: std::mem::size_of::<$ty>(),
            fields: vec![$(
                (
                    $crate::shader_layout::rust_layout!(@member $field $(, $member)?),
                    std::mem::offset_of!($ty, $field),
                )
            ),*],
        }
    };
    (@member $field:ident) => { stringify!($field) };
    (@member $field:ident, $member:literal) => { $member };
}
pub(crate) use rust_layout;

/// Panics unless `rust` is laid out as the struct `wgsl_struct` of `shader` (composed with
/// `fiber_model` where it shades strands): the same size, a size that the WGSL struct's
/// alignment divides (so that arrays of either have one stride), and every WGSL member but
/// padding (`_pad…`) at the offset of the Rust field named for it, no Rust field left over.
pub(crate) fn assert_same_layout(
    shader: &Wgsl,
    fiber_model: Option<&Wgsl>,
    wgsl_struct: &str,
    rust: &RustLayout,
) {
    let module = compose(shader, fiber_model);
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .expect("the composed module lays out");
    let (handle, members, span) = module
        .types
        .iter()
        .find_map(|(handle, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, span }
                if ty.name.as_deref() == Some(wgsl_struct) =>
            {
                Some((handle, members, *span))
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("{} declares no struct {wgsl_struct}", shader.file));
    let what = format!("{} (Rust) vs {wgsl_struct} ({})", rust.name, shader.file);
    assert_eq!(rust.size, span as usize, "{what}: size");
    let alignment = layouter[handle].alignment;
    assert!(
        alignment.is_aligned(rust.size as u32),
        "{what}: size {} is not a multiple of the WGSL alignment {alignment}",
        rust.size
    );
    let named: Vec<(&str, u32)> = members
        .iter()
        .filter_map(|m| Some((m.name.as_deref()?, m.offset)))
        .filter(|(name, _)| !name.starts_with("_pad"))
        .collect();
    for &(member, offset) in &named {
        let field = rust.fields.iter().find(|(name, _)| *name == member);
        let Some(&(_, rust_offset)) = field else {
            panic!("{what}: no Rust field is given for member `{member}`")
        };
        assert_eq!(rust_offset, offset as usize, "{what}: offset of `{member}`");
    }
    for (field, _) in &rust.fields {
        assert!(
            named.iter().any(|(member, _)| member == field),
            "{what}: WGSL has no member `{field}`"
        );
    }
}
