// GL-only entry point: one fragment per pixel of the tile being drawn, offset
// by the tile's origin in the film. Fragment row y is image row y (row 0 on
// top), so glReadPixels returns rows top first.
layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy) + ivec2(frame.tile_origin_x, frame.tile_origin_y);
    out_radiance = vec4(render_pixel(pixel.x, pixel.y), 1.0f);
}
