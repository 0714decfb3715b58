// GL-only entry point: one fragment per pixel of the tile being drawn, offset
// by the tile's origin in the film. Fragment row y is image row y (row 0 on
// top), so glReadPixels returns rows top first.
layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy) + ivec2(frame.tile_origin_x, frame.tile_origin_y);
    vec3 radiance = render_pixel(pixel.x, pixel.y);
    // The render outputs, when asked for (outputs_layout.glsl), in the tile's
    // storage block; written before the guard below, which then covers them.
    if (RENDER_OUTPUTS) {
        int base = (int(gl_FragCoord.y) * frame.tile_width + int(gl_FragCoord.x)) * OUTPUT_FLOATS;
        for (int k = 0; k < OUTPUT_FLOATS; ++k) tile_outputs[base + k] = pixel_output_value(k);
    }
    // Mesa's llvmpipe ends every loop of an invocation, silently, once the
    // invocation has run 65535 loop iterations in all (its loop limiter; see
    // docs/architecture.md, "GL loop limit"). This last loop of
    // frame.loop_guard_iterations (2) iterations finishes only if that budget
    // was not spent: alpha 0 marks a pixel whose loops may have been cut, which
    // the renderer recomputes on the CPU. Other drivers always finish it.
    int guard = 0;
    while (guard < frame.loop_guard_iterations) ++guard;
    out_radiance = vec4(radiance, guard == frame.loop_guard_iterations ? 1.0f : 0.0f);
}
