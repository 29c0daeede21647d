#version 330 core
// u_gain scales the texture (exposure changes); grey textures are stored as one channel.
in vec2 v_uv;
uniform sampler2D u_texture;
uniform bool u_grey;
uniform float u_gain;
out vec4 o_color;
void main() {
  vec4 t = texture(u_texture, v_uv);
  vec3 rgb = u_grey ? vec3(t.r) : t.rgb;
  o_color = vec4(clamp(rgb * u_gain, 0.0, 1.0), 1.0);
}
