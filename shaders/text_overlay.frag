#version 450 core
// The view copied texel for texel with a text label blended over a rectangle of it (the on-screen
// messages of play/calibrate, drawn into the view so that they pass through the light field
// compositor). Row 0 is the top row in the view, the label and the output alike, so no flips.

layout(binding = 0) uniform sampler2D u_view;
layout(binding = 1) uniform sampler2D u_label;
layout(location = 0) uniform ivec2 u_box_origin;  // the label's top-left corner in output texels
layout(location = 1) uniform ivec2 u_box_size;    // the label's size in output texels (its texture may be narrower when
                             // the view's pixels are not square)

out vec4 colour;

void main() {
  const ivec2 texel = ivec2(floor(gl_FragCoord.xy));
  const vec4 view = texelFetch(u_view, texel, 0);
  const ivec2 in_box = texel - u_box_origin;
  if (any(lessThan(in_box, ivec2(0))) || any(greaterThanEqual(in_box, u_box_size))) {
    colour = view;
    return;
  }
  const vec4 label = texture(u_label, (vec2(in_box) + 0.5) / vec2(u_box_size));
  colour = vec4(mix(view.rgb, label.rgb, label.a), view.a);
}
