#version 330 core
// Expands each segment into a quad `width` pixels wide (core profile has no wide lines).
// Segments crossing the near plane are clipped first so the perspective divide stays valid.
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
in vec4 g_color[];
in float g_width[];
uniform vec2 u_viewport;
out vec4 f_color;

vec4 clipToNear(vec4 inside, vec4 outside) {
  // Near plane in clip space: z = -w.
  float da = inside.z + inside.w, db = outside.z + outside.w;
  return mix(inside, outside, da / (da - db));
}

void main() {
  vec4 p0 = gl_in[0].gl_Position, p1 = gl_in[1].gl_Position;
  bool in0 = p0.z >= -p0.w, in1 = p1.z >= -p1.w;
  if (!in0 && !in1) return;
  if (!in0) p0 = clipToNear(p1, p0);
  if (!in1) p1 = clipToNear(p0, p1);
  vec2 s0 = p0.xy / p0.w * u_viewport * 0.5, s1 = p1.xy / p1.w * u_viewport * 0.5;
  vec2 dir = s1 - s0;
  float len = length(dir);
  dir = len > 1e-6 ? dir / len : vec2(1.0, 0.0);
  vec2 n = vec2(-dir.y, dir.x);
  vec2 o0 = n * g_width[0] * 0.5 / (u_viewport * 0.5) * p0.w;
  vec2 o1 = n * g_width[1] * 0.5 / (u_viewport * 0.5) * p1.w;
  // Extend half a width along the segment so consecutive segments of a polyline overlap at joints.
  vec2 e0 = dir * g_width[0] * 0.5 / (u_viewport * 0.5) * p0.w;
  vec2 e1 = dir * g_width[1] * 0.5 / (u_viewport * 0.5) * p1.w;
  f_color = g_color[0];
  gl_Position = vec4(p0.xy + o0 - e0, p0.zw); EmitVertex();
  gl_Position = vec4(p0.xy - o0 - e0, p0.zw); EmitVertex();
  f_color = g_color[1];
  gl_Position = vec4(p1.xy + o1 + e1, p1.zw); EmitVertex();
  gl_Position = vec4(p1.xy - o1 + e1, p1.zw); EmitVertex();
  EndPrimitive();
}
