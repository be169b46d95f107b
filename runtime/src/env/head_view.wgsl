// The head seen from the view (head.wgsl draws it before the hair's passes): where it is, and
// which fiber fragments it hides.
#define_import_path strandlight::head_view

#import strandlight::occupancy_map::view_depth
#import strandlight::strand_quads::VertexOut
#import strandlight::view_binding::{view, head_position}

fn frame_has_head() -> bool {
    return view.skin.w > 0.5;
}

// The head's position (w: 1 on the head) at `pixel`.
fn head_at(pixel: vec2<i32>) -> vec4<f32> {
    if (!frame_has_head()) { return vec4<f32>(0.0); }
    return textureLoad(head_position, pixel, 0);
}

// Whether the fiber fragment `in` lies behind the head along its pixel's ray (the occupancy
// passes and the transparent view have no depth attachment: they test in the shader).
fn behind_head(in: VertexOut) -> bool {
    let head = head_at(vec2<i32>(in.clip.xy));
    return head.w > 0.0 && view_depth(in.world) > view_depth(head.xyz);
}
