#version 330 core
// Instanced voxel cubes: one unit cube, offset and coloured per instance, Lambert shaded.
layout(location = 0) in vec3 a_corner;  // unit cube vertex in [-0.5, 0.5]^3
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 i_center;
layout(location = 3) in vec4 i_color;
layout(location = 4) in float i_hidden;  // bit f: face f (gl_VertexID / 6) is inside the solid
uniform mat4 u_mvp;
uniform float u_size;
uniform vec3 u_light_dir;  // world frame, towards the light
out vec4 v_color;
void main() {
  if (((int(i_hidden) >> (gl_VertexID / 6)) & 1) != 0) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: the triangle is dropped
    v_color = vec4(0.0);
    return;
  }
  gl_Position = u_mvp * vec4(i_center + a_corner * u_size, 1.0);
  float lambert = max(dot(a_normal, normalize(u_light_dir)), 0.0);
  v_color = vec4(i_color.rgb * (0.45 + 0.55 * lambert), i_color.a);
}
