// Display pass of the GL display stage (issue 8): one invocation per pixel
// applies display_pixel (effects/display/display.glsl: exposure, tone curve on
// luminance, sRGB OETF) to the linear radiance and stores the 8-bit value
// display_quantize(v, t) (the pixel's ordered dither threshold t, or 1/2:
// rounding), as in apply_display (effects/display/display.cpp), as q / 255 into an
// RGBA8 image (the UNORM conversion of q / 255 gives back q exactly). display.glsl is prepended by gl_backend.cpp.

layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0) uniform sampler2D u_radiance;  // RGBA32F, texel row = image row
layout(binding = 1) uniform sampler2D u_addend;    // RGBA32F, added to u_radiance when u_has_addend
layout(rgba8, binding = 0) writeonly uniform image2D u_display;

uniform ivec2 u_size;
uniform float u_exposure;
uniform int u_curve;
uniform float u_white;
uniform bool u_has_addend;
uniform bool u_dither;  // ordered dithering (display_quantize); off: rounding
uniform int u_origin;   // texel p is image pixel p - u_origin (the glare's margin)

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
    vec3 radiance = texelFetch(u_radiance, p, 0).rgb;
    if (u_has_addend) radiance += texelFetch(u_addend, p, 0).rgb;
    vec3 v = display_pixel(radiance, u_exposure, u_curve, u_white);
    float t = u_dither ? display_dither_threshold(p.x - u_origin, p.y - u_origin) : 0.5f;
    vec3 q = vec3(display_quantize(v.r, t), display_quantize(v.g, t), display_quantize(v.b, t));
    imageStore(u_display, p, vec4(q / 255.0f, 1.0f));
}
