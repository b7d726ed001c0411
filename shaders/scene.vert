// scene.vert - world-space scene geometry (lpv_vertex) through one view-projection.
// Used by the reflective shadow maps and the camera G-buffer.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec2 a_uv1;
layout(location = 4) in vec4 a_tangent;
layout(location = 5) in vec4 a_color; // COLOR_0 (material.glsl reads it where u_vertex_color is 1)

uniform mat4 u_view_proj;

out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
out vec2 v_uv1;
out vec4 v_tangent;
out vec4 v_color;

void main()
{
    v_position = a_position;
    v_normal = a_normal;
    v_uv = a_uv;
    v_uv1 = a_uv1;
    v_tangent = a_tangent;
    v_color = a_color;
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
