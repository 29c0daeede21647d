#version 330 core
// Round points: fragments outside the inscribed disc are dropped.
in vec4 v_color;
uniform bool u_round;
out vec4 o_color;
void main() {
  if (u_round && length(gl_PointCoord - vec2(0.5)) > 0.5) discard;
  o_color = v_color;
}
