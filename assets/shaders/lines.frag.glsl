#version 330 core
in vec4 f_color;
out vec4 o_color;
void main() { o_color = f_color; }
