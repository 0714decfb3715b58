// The core's light helpers shared by the effects' terms (EFFECT_GLSL_TERMS):
// the homogeneous medium's transmittance and the film footprint of lamp cores
// smaller than a pixel.

// Beer-Lambert transmittance exp(-sigma_t t) of the homogeneous medium.
// t = NO_HIT (escaping ray) gives 0 on every channel with sigma_t > 0.
vec3 transmittance(float t) {
    if (!HAS_MEDIUM) return vec3(1.0f);
    vec3 sigma_t = vec3(frame.sigma_t);
    if (t >= NO_HIT) {  // explicit: exp(-0 * inf) may be NaN once a compiler reassociates
        return vec3(sigma_t.x > 0.0f ? 0.0f : 1.0f, sigma_t.y > 0.0f ? 0.0f : 1.0f, sigma_t.z > 0.0f ? 0.0f : 1.0f);
    }
    if (GREY_MEDIUM) return vec3(exp(-sigma_t.x * t));  // the channels are equal: one exp, not three
    return exp(-sigma_t * t);
}

// ---- Lamp cores smaller than a pixel ---------------------------------------
// A lamp's disc that projects smaller than LAMP_SUBPIXEL_RADIUS pixels is
// missed or hit at random by one ray through the pixel's centre (a distant
// headlight would flicker or vanish). Such cores are box-filtered instead:
// the disc becomes the square of the same area on the image plane, and each
// pixel gets the lamp's radiance times the fraction of its area that square
// covers. The square's area is the disc's projected area, pi r^2 / (d^2
// cos^3 theta) at distance d and off-axis angle theta (a solid angle Omega
// projects to Omega / cos^3 theta on the plane at distance 1), so the energy
// over all pixels is exactly the lamp's, L pi r^2 / d^2 (issue 8: the
// glare's point sources must carry their true energy).

// Position of `rel` (a point relative to the camera) on the film in
// continuous pixel units (x right, row down; pixel (x, row) spans
// [x, x + 1] x [row, row + 1]) in .xy, the projected square's half side in
// pixels in .z; .z = NO_HIT for points not in front of the camera.
vec3 lamp_film_square(vec3 rel, float r) {
    vec3 forward = vec3(frame.camera_forward);
    vec3 right = vec3(frame.camera_right);
    vec3 up = vec3(frame.camera_up);
    float z = dot(rel, forward);
    float d = length(rel);
    if (z <= r || d <= r) return vec3(0.0f, 0.0f, NO_HIT);
    float sx = dot(rel, right) / (z * dot(right, right));
    float sy = dot(rel, up) / (z * dot(up, up));
    float width = float(frame.film_width);
    float height = float(frame.film_height);
    float pixel = 2.0f * length(up) / height;  // pixel side on the plane at distance 1
    float cos_theta = z / d;
    float disc_radius = r / (d * cos_theta * sqrt(cos_theta));  // equal projected area
    float half_side = 0.5f * sqrt(PI) * disc_radius / pixel;
    return vec3(0.5f * (sx + 1.0f) * width, 0.5f * (1.0f - sy) * height, half_side);
}

// True when the lamp (centre relative to the camera, radius r) is drawn by
// lamp_subpixel_cores, not by the pixel's ray.
bool lamp_is_subpixel(vec3 rel, float r) {
    float half_side = lamp_film_square(rel, r).z;
    return half_side < 0.5f * sqrt(PI) * LAMP_SUBPIXEL_RADIUS;
}

// Length of [c - h, c + h] inside the pixel [i, i + 1]: min(2 h, u + h,
// 1 - u + h, 1) with u = c - i, never below 0. Not min(i + 1, c + h) -
// max(i, c - h), whose c +- h round to c when h is below the float spacing
// of c (a 5 mm lamp 100 km away is 3e-6 pixel wide): an interval inside the
// pixel keeps its exact width 2 h, whatever h.
float pixel_interval_overlap(float c, float h, int i) {
    float u = c - float(i);
    return max(min(min(2.0f * h, 1.0f), min(u + h, (1.0f - u) + h)), 0.0f);
}

// Fraction of pixel (x, row) covered by the lamp's film square (0 when the
// lamp is resolved: the ray draws it).
float lamp_pixel_coverage(vec3 rel, float r, int x, int row) {
    vec3 sq = lamp_film_square(rel, r);
    if (!(sq.z < 0.5f * sqrt(PI) * LAMP_SUBPIXEL_RADIUS)) return 0.0f;
    return pixel_interval_overlap(sq.x, sq.z, x) * pixel_interval_overlap(sq.y, sq.z, row);
}

// Weight of a sub-pixel core in pixel (x, row): its coverage times the
// ratio of the solid angle of a pixel at the lamp's centre to this pixel's,
// (cos theta_lamp / cos theta_pixel)^3, so that the energy the pixels get,
// sum of radiance x pixel solid angle, is the lamp's whatever the pixel.
float lamp_pixel_weight(vec3 rel, float r, int x, int row) {
    float cover = lamp_pixel_coverage(rel, r, x, row);
    if (cover <= 0.0f) return 0.0f;
    vec3 forward = vec3(frame.camera_forward);
    float ratio = (dot(rel, forward) / length(rel)) / dot(camera_ray_direction(x, row), forward);
    return cover * ratio * ratio * ratio;
}
