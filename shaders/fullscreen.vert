// One triangle covering the viewport; no vertex buffers needed.
void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0f - 1.0f, 0.0f, 1.0f);
}
