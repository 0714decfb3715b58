// The display stage (issue 8, effects/display/physics.md): exposure, the eye's glare,
// tone curve and sRGB, on the CPU or on the GL backend. The decisions (the
// exposure, the pupil, which pixels' glare matters) are made here once, on the
// CPU, so that both backends show the same image.
#include "display_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include "backends.hpp"
#include "numerics.hpp"
#include "shader_cpp.hpp"

namespace airlight {

namespace {

double elapsed_ms(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Radiance as display_pixel treats it: NaN and negative give 0, values above
// 1e30 give 1e30.
float sanitised(float v) { return v > 0.0f ? std::min(v, 1e30f) : 0.0f; }

// Glare kernels by (pupil mm, eyelashes, pixel angle): a kernel costs about
// 0.03 s, an animation reuses it every frame (the automatic pupil is rounded
// to 0.05 mm for that). A few entries are kept.
std::shared_ptr<const GlareKernel> cached_kernel(double pupil_mm, bool eyelashes, double pixel_angle) {
    using Key = std::tuple<double, bool, double>;
    static std::mutex mutex;
    static std::map<Key, std::shared_ptr<const GlareKernel>> cache;
    const Key key{pupil_mm, eyelashes, pixel_angle};
    {
        std::lock_guard<std::mutex> lock(mutex);
        auto it = cache.find(key);
        if (it != cache.end()) return it->second;
    }
    GlareOptions options;
    options.pupil_diameter_mm = pupil_mm;
    options.eyelashes = eyelashes;
    auto kernel = std::make_shared<const GlareKernel>(glare_kernel_rgb(options, pixel_angle));
    std::lock_guard<std::mutex> lock(mutex);
    if (cache.size() >= 16) cache.clear();
    cache[key] = kernel;
    return kernel;
}

// Adds weight * kernel[c] centred at (x, y) into out channel c (zero padding).
void splat(Image& out, const GlareKernel& kernel, int x, int y, int c, double weight) {
    const int r = kernel.radius, size = kernel.size();
    const int row0 = std::max(0, r - y), row1 = std::min(size - 1, r + (out.height - 1 - y));
    const int col0 = std::max(0, r - x), col1 = std::min(size - 1, r + (out.width - 1 - x));
    for (int row = row0; row <= row1; ++row) {
        float* dst = &out.rgb[(size_t(y + row - r) * out.width + size_t(x - r)) * 3 + c];
        const double* w = &kernel.weights[c][size_t(row) * size];
        for (int col = col0; col <= col1; ++col) dst[size_t(col) * 3] += float(weight * w[col]);
    }
}

}  // namespace

Image extend_edges(const Image& image, int margin) {
    Image out;
    out.width = image.width + 2 * margin;
    out.height = image.height + 2 * margin;
    out.rgb.resize(size_t(out.width) * size_t(out.height) * 3);
    for (int y = 0; y < out.height; ++y) {
        const int sy = std::clamp(y - margin, 0, image.height - 1);
        for (int x = 0; x < out.width; ++x) {
            const int sx = std::clamp(x - margin, 0, image.width - 1);
            const float* src = &image.rgb[(size_t(sy) * image.width + sx) * 3];
            std::copy(src, src + 3, &out.rgb[(size_t(y) * out.width + x) * 3]);
        }
    }
    return out;
}

Image crop(const Image& image, int x0, int y0, int width, int height) {
    Image out{width, height, std::vector<float>(size_t(width) * size_t(height) * 3)};
    for (int y = 0; y < height; ++y) {
        const float* src = &image.rgb[(size_t(y + y0) * image.width + x0) * 3];
        std::copy(src, src + size_t(width) * 3, &out.rgb[size_t(y) * width * 3]);
    }
    return out;
}

GlareSplit split_for_fft(Image image, const GlareKernel& kernel) {
    GlareSplit split;
    for (float& v : image.rgb) v = sanitised(v);
    std::vector<float> values;
    values.reserve(image.rgb.size());
    for (float v : image.rgb)
        if (v > 0.0f) values.push_back(v);
    if (values.empty()) {
        split.clipped = std::move(image);
        return split;
    }
    // C = 1e4 x the median of the positive channel values.
    auto median = values.begin() + std::ptrdiff_t(values.size() / 2);
    std::nth_element(values.begin(), median, values.end());
    const float cap = std::min(1e4f * *median, 1e30f);
    bool any = false;
    split.excess = Image{image.width, image.height, std::vector<float>(image.rgb.size(), 0.0f)};
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            for (int c = 0; c < 3; ++c) {
                float& v = image.rgb[(size_t(y) * image.width + x) * 3 + c];
                if (v <= cap) continue;
                splat(split.excess, kernel, x, y, c, double(v) - double(cap));
                v = cap;
                any = true;
            }
        }
    }
    if (!any) split.excess = Image{};
    split.clipped = std::move(image);
    return split;
}

Image glare_exact(const Image& linear, const GlareKernel& kernel, int threads) {
    if (linear.width < 1 || linear.height < 1) return linear;
    const int r = kernel.radius;
    const GlareSplit split = split_for_fft(extend_edges(linear, r), kernel);
    Image out = convolve_glare_fft(split.clipped, kernel, threads);
    if (!split.excess.rgb.empty())
        for (size_t i = 0; i < out.rgb.size(); ++i) out.rgb[i] += split.excess.rgb[i];
    return crop(out, r, r, linear.width, linear.height);
}

DisplayResponse::DisplayResponse(ToneCurve curve, float white) : curve_id_(tone_curve_shader_id(curve)), white_(white) {
    const int per_decade = 64, decades = 11;
    const int n = per_decade * decades + 1;
    log_lo_ = std::log(double(white) * 1e-8);
    step_ = std::log(10.0) / per_decade;
    gain_envelope_.assign(size_t(n), 0.0);
    bend_envelope_.assign(size_t(n), 0.0);
    double g_max = 0.0, h_max = 0.0;
    const double half = 0.5 * step_;
    for (int k = n - 1; k >= 0; --k) {
        const double y = std::exp(log_lo_ + step_ * k);
        const double y0 = y * std::exp(-half), y1 = y * std::exp(half);
        const double f0 = double(shader::tone_curve(curve_id_, float(y0), white_));
        const double f1 = double(shader::tone_curve(curve_id_, float(y1), white_));
        const double slope = (f1 - f0) / (y1 - y0);  // f'(y), central difference
        g_max = std::max(g_max, gain(y));
        h_max = std::max(h_max, std::abs(slope - gain(y)));
        gain_envelope_[size_t(k)] = 1.05 * g_max;
        bend_envelope_[size_t(k)] = 1.05 * h_max;
    }
}

double DisplayResponse::gain(double y) const {
    // Below 1e-8 white every curve is linear (f(y) ~ f'(0) y); g is taken there.
    const double lo = double(white_) * 1e-8;
    const double at = std::max(y, lo);
    return double(shader::tone_curve(curve_id_, float(at), white_)) / at;
}

double DisplayResponse::envelope(const std::vector<double>& table, double y) const {
    const double k = y > 0.0 ? (std::log(y) - log_lo_) / step_ : -1.0;
    if (k <= 0.0) return table.front();
    const size_t i = size_t(k);
    return i >= table.size() ? table.back() : table[i];  // beyond 1e3 white: g, |f' - g| <= 1e-3 / white
}

double DisplayResponse::sensitivity(double c_lo, double y_lo, double y_hi, double chroma) const {
    // sRGB's slope at the darkest display value the tile can take (IEC 61966-2-1).
    const double u = std::max(c_lo, 0.0) * gain(std::max(y_hi, 0.0));
    const double srgb_slope = u >= 1.0 ? 0.0 : (u <= 0.0031308 ? 12.92 : 1.055 / 2.4 * std::pow(u, -1.4 / 2.4));
    const double y = std::max(y_lo, 0.0);
    return srgb_slope * (envelope(gain_envelope_, y) + chroma * envelope(bend_envelope_, y));
}

namespace {

// Per tile of the image (side `tile` pixels), per channel, the largest and
// smallest sanitised radiance (NaN and negative: 0; above 1e30: 1e30, as
// display_pixel treats them), and the largest difference between a pixel of
// the tile and its right or lower neighbour (any channel).
struct TileRanges {
    int nx = 0, ny = 0;
    std::vector<std::array<float, 3>> hi, lo;
    std::vector<float> step;
    std::vector<float> y_lo, y_hi;  // Rec. 709 luminance
    std::vector<float> chroma;      // max over pixels and channels of c / Y (0 where Y = 0)
};

// The kernel's off-centre weight by L1 distance k = |dx| + |dy| (index k,
// the largest over the channels), and its sum: the most any pixel can lose.
struct KernelProfile {
    std::vector<double> mass;
    double spread = 0.0;
};

KernelProfile kernel_profile(const GlareKernel& kernel) {
    KernelProfile p;
    const int r = kernel.radius;
    p.mass.assign(size_t(2 * r + 1), 0.0);
    for (int c = 0; c < 3; ++c) {
        std::vector<double> m(p.mass.size(), 0.0);
        for (int row = 0; row < kernel.size(); ++row)
            for (int col = 0; col < kernel.size(); ++col)
                m[size_t(std::abs(row - r) + std::abs(col - r))] += kernel.at(c, row, col);
        for (size_t k = 1; k < m.size(); ++k) p.mass[k] = std::max(p.mass[k], m[k]);
    }
    for (size_t k = 1; k < p.mass.size(); ++k) p.spread += p.mass[k];
    return p;
}

// Bound on |(K * B - B)(p)| = |sum_d K(d) (B_{p+d} - B_p)| when B changes by
// at most `step` between neighbouring pixels and by at most `range` over the
// window: |B_{p+d} - B_p| <= min(step |d|_1, range) (a path of |d|_1 steps
// inside the window).
double glare_change_bound(const KernelProfile& profile, double step, double range) {
    double e = 0.0;
    for (size_t k = 1; k < profile.mass.size(); ++k) e += profile.mass[k] * std::min(step * double(k), range);
    return e;
}

TileRanges tile_ranges(const Image& image, int tile) {
    TileRanges t;
    t.nx = (image.width + tile - 1) / tile;
    t.ny = (image.height + tile - 1) / tile;
    t.hi.assign(size_t(t.nx) * t.ny, {0.0f, 0.0f, 0.0f});
    t.lo.assign(size_t(t.nx) * t.ny, {1e30f, 1e30f, 1e30f});
    t.step.assign(size_t(t.nx) * t.ny, 0.0f);
    t.y_lo.assign(size_t(t.nx) * t.ny, 1e30f);
    t.y_hi.assign(size_t(t.nx) * t.ny, 0.0f);
    t.chroma.assign(size_t(t.nx) * t.ny, 0.0f);
    const int w = image.width, h = image.height;
    for (int y = 0; y < h; ++y) {
        const size_t row = size_t(y / tile) * t.nx;
        for (int x = 0; x < w; ++x) {
            const float* p = &image.rgb[(size_t(y) * w + x) * 3];
            const float* right = x + 1 < w ? p + 3 : p;
            const float* below = y + 1 < h ? p + size_t(w) * 3 : p;
            const size_t i = row + size_t(x / tile);
            const float r = sanitised(p[0]), g = sanitised(p[1]), b = sanitised(p[2]);
            const float lum = 0.2126f * r + 0.7152f * g + 0.0722f * b;
            t.y_lo[i] = std::min(t.y_lo[i], lum);
            t.y_hi[i] = std::max(t.y_hi[i], lum);
            if (lum > 0.0f) t.chroma[i] = std::max(t.chroma[i], std::max({r, g, b}) / lum);
            for (int c = 0; c < 3; ++c) {
                const float v = sanitised(p[c]);
                t.hi[i][c] = std::max(t.hi[i][c], v);
                t.lo[i][c] = std::min(t.lo[i][c], v);
                t.step[i] = std::max({t.step[i], std::abs(sanitised(right[c]) - v), std::abs(sanitised(below[c]) - v)});
            }
        }
    }
    return t;
}

// The bound e_t of GlarePlan for tile (tx, ty) when each tile u of its
// neighbourhood is clipped at min(caps[u], cap) (beyond the border: the edge
// tiles, whose values extend_edges repeats), with the slope test: returns e_t
// when e_t * exposure * slope <= half a step, else a negative value.
double tile_bound(const TileRanges& t, const std::vector<double>& caps, int tx, int ty, double cap,
                  const KernelProfile& profile, double exposure, const DisplayResponse& response) {
    constexpr double kHalfStep = 0.5 / 255.0;
    std::array<double, 3> hi{0.0, 0.0, 0.0}, lo{1e30, 1e30, 1e30};
    double step = 0.0;
    bool clipped = false;  // some value is clipped: B's steps are no longer v's
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            const int x = std::clamp(tx + dx, 0, t.nx - 1), y = std::clamp(ty + dy, 0, t.ny - 1);
            const size_t i = size_t(y) * t.nx + x;
            const double c_u = std::min(caps[i], cap);
            step = std::max(step, double(t.step[i]));
            clipped |= double(std::max({t.hi[i][0], t.hi[i][1], t.hi[i][2]})) > c_u;
            for (int c = 0; c < 3; ++c) {
                hi[c] = std::max(hi[c], std::min(double(t.hi[i][c]), c_u));
                lo[c] = std::min(lo[c], std::min(double(t.lo[i][c]), c_u));
            }
        }
    }
    const size_t own = size_t(ty) * t.nx + tx;
    const double own_cap = std::min(caps[own], cap);
    double range = 0.0, own_low = 1e30;
    for (int c = 0; c < 3; ++c) {
        range = std::max(range, hi[c] - lo[c]);
        own_low = std::min(own_low, std::min(double(t.lo[own][c]), own_cap));
    }
    const double e = clipped ? profile.spread * range : glare_change_bound(profile, step, range);
    // The tile's levels after a change of at most e (clipping at own_cap lowers luminance at most to
    // own_cap's and can raise the chroma to 1 / 0.0722, the bluest possible).
    const bool own_clipped = double(std::max({t.hi[own][0], t.hi[own][1], t.hi[own][2]})) > own_cap;
    const double c_lo = exposure * (own_low - e);
    const double y_lo = exposure * (std::min(double(t.y_lo[own]), own_cap) - e);
    const double y_hi = exposure * (std::min(double(t.y_hi[own]), own_cap) + e);
    // c / Y <= 1 / 0.0722 always (Y >= 0.0722 c); after the change, (c + e) / (Y - e).
    constexpr double kMaxChroma = 1.0 / 0.0722;
    const double raw_y_lo = std::min(double(t.y_lo[own]), own_cap);
    const double chroma = own_clipped || raw_y_lo <= e
                              ? kMaxChroma
                              : std::min(kMaxChroma, (double(t.chroma[own]) * raw_y_lo + e) / (raw_y_lo - e));
    return e * exposure * response.sensitivity(c_lo, y_lo, y_hi, chroma) > kHalfStep ? -1.0 : e;
}

// Per-tile thresholds (GlarePlan::tile_threshold): start with none (every
// cap above the image); a tile whose bound fails gets the largest cap c that
// makes it pass when its whole neighbourhood is clipped at c (bisection in
// log c), and its neighbours' caps are lowered to c. Caps only decrease, and
// clipping everything at 0 passes, so this ends; a few rounds settle it (a
// lowered cap can lower a neighbourhood's minimum). Returns false when it
// has not settled after `rounds` rounds.
bool choose_tile_thresholds(const TileRanges& t, double top, const KernelProfile& spread, double exposure,
                            const DisplayResponse& slope, std::vector<double>& caps, double& worst) {
    const double none = top * 2.0 + 1.0;
    caps.assign(size_t(t.nx) * t.ny, none);
    for (int round = 0; round < 64; ++round) {
        bool changed = false;
        worst = 0.0;
        for (int ty = 0; ty < t.ny; ++ty) {
            for (int tx = 0; tx < t.nx; ++tx) {
                const double e = tile_bound(t, caps, tx, ty, none, spread, exposure, slope);
                if (e >= 0.0) {
                    worst = std::max(worst, e);
                    continue;
                }
                double pass = 0.0, fail = top;
                if (tile_bound(t, caps, tx, ty, top * 1e-9, spread, exposure, slope) >= 0.0) {
                    pass = top * 1e-9;
                    for (int it = 0; it < 30 && fail > pass * 1.02; ++it) {
                        const double mid = std::sqrt(pass * fail);
                        (tile_bound(t, caps, tx, ty, mid, spread, exposure, slope) >= 0.0 ? pass : fail) = mid;
                    }
                }
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int x = tx + dx, y = ty + dy;
                        if (x < 0 || y < 0 || x >= t.nx || y >= t.ny) continue;
                        double& cap = caps[size_t(y) * t.nx + x];
                        if (cap > pass) {
                            cap = pass;
                            changed = true;
                        }
                    }
                }
            }
        }
        if (!changed) return true;
    }
    return false;
}

}  // namespace

GlarePlan plan_glare(const Image& linear, const DisplaySettings& settings, float exposure, double fov_y_degrees,
                     int threads) {
    GlarePlan plan;
    if (!settings.glare.enabled) return plan;
    if (!(fov_y_degrees > 0.0 && fov_y_degrees < 180.0))
        throw std::invalid_argument("camera.fov_y: must be in (0, 180) degrees for the glare's angular scale");
    if (settings.glare.pupil_diameter_mm) validate_pupil_diameter(*settings.glare.pupil_diameter_mm);
    if (!(exposure > 0.0f) || linear.width < 1 || linear.height < 1) return plan;  // nothing is shown
    plan.enabled = true;
    if (settings.glare.pupil_diameter_mm) {
        plan.pupil_diameter_mm = *settings.glare.pupil_diameter_mm;
    } else {
        // Adaptation luminance: the log-average luminance (auto_exposure with key 1 is its inverse).
        const double log_average = 1.0 / double(auto_exposure(linear, 1.0f, threads));
        // Rounded to 0.05 mm (about 1 % of the Airy core's size) so that the frames of an animation share
        // kernels.
        const double pupil = pupil_diameter_from_luminance(std::max(kLuminousEfficacy * log_average, 1e-30));
        plan.pupil_diameter_mm = std::round(pupil * 20.0) / 20.0;
    }
    plan.pixel_angle = camera_pixel_angle(fov_y_degrees, linear.height);
    plan.kernel = cached_kernel(plan.pupil_diameter_mm, settings.glare.eyelashes, plan.pixel_angle);
    const GlareKernel& kernel = *plan.kernel;
    const KernelProfile spread = kernel_profile(kernel);
    const float white = settings.white ? *settings.white : default_white(settings.curve);
    const DisplayResponse slope(settings.curve, white);
    plan.tile = std::max(kernel.radius, 1);
    const TileRanges tiles = tile_ranges(linear, plan.tile);
    plan.tiles_x = tiles.nx;
    double top = 0.0;
    for (const auto& hi : tiles.hi) top = std::max({top, double(hi[0]), double(hi[1]), double(hi[2])});
    if (kernel.radius == 0 || spread.spread <= 0.0 ||
        top <= 0.0) {  // a one-pixel kernel or a black image: nothing moves
        plan.tile_threshold.assign(size_t(tiles.nx) * tiles.ny, float(top));
        return plan;
    }
    std::vector<double> caps;
    if (!choose_tile_thresholds(tiles, top, spread, double(exposure), slope, caps, plan.error_bound)) {
        std::fill(caps.begin(), caps.end(), 0.0);  // unsettled: spread everything (the exact convolution)
        plan.error_bound = 0.0;
    }
    plan.tile_threshold.assign(caps.begin(), caps.end());
    for (float& c : plan.tile_threshold) c = std::min(c, 1e30f);
    long long sources = 0;
    for (int y = 0; y < linear.height; ++y) {
        for (int x = 0; x < linear.width; ++x) {
            const float cap = plan.threshold_at(x, y);
            const float* p = &linear.rgb[(size_t(y) * linear.width + x) * 3];
            if (sanitised(p[0]) > cap || sanitised(p[1]) > cap || sanitised(p[2]) > cap) ++sources;
        }
    }
    plan.sources = sources;
    return plan;
}

bool glare_prefers_sparse(const Image& linear, const GlarePlan& plan) {
    if (!plan.kernel) return false;
    // Cost model, in multiply-adds: splatting the sources is 3 (2r + 1)^2 per
    // source (those in the r-pixel margin of extend_edges included, about
    // 2 r (w + h) / (w h) more); the FFT path is about 6 complex 2-D
    // transforms of the padded image, ~ 30 w h log2(w h) real operations.
    const int size = plan.kernel->size();
    const double pixels = double(linear.width) * double(linear.height);
    const double margin = 1.0 + 2.0 * plan.kernel->radius * double(linear.width + linear.height) / pixels;
    const double splat_cost = double(plan.sources) * margin * 3.0 * double(size) * double(size);
    const double fft_cost = 30.0 * pixels * std::log2(std::max(pixels, 2.0));
    return splat_cost < fft_cost;
}

Image apply_glare_plan(const Image& linear, const GlarePlan& plan, int threads, std::string* method) {
    auto say = [&](const char* m) {
        if (method != nullptr) *method = m;
    };
    if (!plan.enabled || plan.sources == 0 || !plan.kernel) {
        say(plan.enabled ? "skipped" : "off");
        return linear;
    }
    const GlareKernel& kernel = *plan.kernel;
    const int r = kernel.radius;
    if (!glare_prefers_sparse(linear, plan)) {
        say("fft");
        return glare_exact(linear, kernel, threads);
    }
    say("sparse");
    // out = B + K * (v - B), B = min(v, T_tile) per channel (GlarePlan), over
    // the image extended by its edges (a margin pixel has the threshold of
    // the edge pixel it copies), then cropped.
    const Image ext = extend_edges(linear, r);
    Image out = ext;
    for (int y = 0; y < ext.height; ++y) {
        for (int x = 0; x < ext.width; ++x) {
            const float cap =
                plan.threshold_at(std::clamp(x - r, 0, linear.width - 1), std::clamp(y - r, 0, linear.height - 1));
            const size_t i = (size_t(y) * ext.width + x) * 3;
            for (int c = 0; c < 3; ++c) out.rgb[i + c] = std::min(sanitised(ext.rgb[i + c]), cap);
        }
    }
    for (int y = 0; y < ext.height; ++y) {
        for (int x = 0; x < ext.width; ++x) {
            const size_t i = (size_t(y) * ext.width + x) * 3;
            for (int c = 0; c < 3; ++c) {
                // The excess over the pixel's own cap, from the unclipped image (splats only add to out).
                const float cap =
                    plan.threshold_at(std::clamp(x - r, 0, linear.width - 1), std::clamp(y - r, 0, linear.height - 1));
                const double v = double(sanitised(ext.rgb[i + c]));
                if (v > double(cap)) splat(out, kernel, x, y, c, v - double(cap));
            }
        }
    }
    return crop(out, r, r, linear.width, linear.height);
}

DisplayImage run_display_stage(const Image& linear, const DisplaySettings& settings, double fov_y_degrees, int threads,
                               GlBackend* gl) {
    validate_display_settings(settings);
    if (linear.width < 0 || linear.height < 0 ||
        linear.rgb.size() != size_t(linear.width) * size_t(linear.height) * 3) {
        throw std::invalid_argument("radiance: size does not match width * height * 3");
    }
    threads = numerics::thread_count(threads);
    DisplayImage result;
    result.width = linear.width;
    result.height = linear.height;
    DisplayReport& report = result.report;
    auto start = std::chrono::steady_clock::now();
    report.exposure = resolve_exposure(linear, settings, threads);
    report.white = settings.white ? *settings.white : default_white(settings.curve);
    const GlarePlan plan = plan_glare(linear, settings, report.exposure, fov_y_degrees, threads);
    report.pupil_diameter_mm = plan.pupil_diameter_mm;
    report.glare_kernel_radius = plan.kernel ? plan.kernel->radius : 0;
    report.glare_threshold = plan.tile_threshold.empty()
                                 ? 0.0
                                 : double(*std::min_element(plan.tile_threshold.begin(), plan.tile_threshold.end()));
    report.glare_error_bound = plan.error_bound;
    report.glare_sources = plan.sources;
    report.glare = settings.glare.enabled ? "skipped" : "off";
    // An image that, with the glare's margin, exceeds the GL driver's textures
    // takes the CPU path (a 1 x 16368 film with glare failed on GL).
    if (gl != nullptr) {
        const int margin = plan.enabled && plan.sources > 0 ? plan.kernel->radius : 0;
        if (std::max(linear.width, linear.height) + 2 * margin > gl->max_texture_size()) gl = nullptr;
    }
    if (gl != nullptr) {
        // Few pixels to spread: the CPU splats them (apply_glare_plan) and the
        // GPU tone-maps. Many: the GPU convolves the whole edge-extended image
        // (glare_exact's split: the clipped image by FFT, the excess of the
        // brightest pixels added as splats) and tone-maps it; the margin is
        // cropped from the bytes.
        GlDisplayJob job;
        GlareSplit split;
        Image splatted;
        int margin = 0;
        job.linear = &linear;
        job.exposure = report.exposure;
        job.curve = tone_curve_shader_id(settings.curve);
        job.white = report.white;
        job.dither = settings.dither;
        if (plan.enabled && plan.sources > 0 && glare_prefers_sparse(linear, plan)) {
            std::string method;
            splatted = apply_glare_plan(linear, plan, threads, &method);
            job.linear = &splatted;
            report.glare = method;
        } else if (plan.enabled && plan.sources > 0) {
            margin = plan.kernel->radius;
            job.origin = margin;
            split = split_for_fft(extend_edges(linear, margin), *plan.kernel);
            job.linear = &split.clipped;
            if (!split.excess.rgb.empty()) job.addend = &split.excess;
            job.glare = plan.kernel.get();
            report.glare = "gl-fft";
        }
        const double plan_ms = elapsed_ms(start);
        GlDisplayOutput out;
        gl->display(job, out);
        if (margin == 0) {
            result.srgb8 = std::move(out.srgb8);
        } else {
            const size_t row = size_t(linear.width) * 3, ext_row = size_t(job.linear->width) * 3;
            result.srgb8.resize(row * size_t(linear.height));
            for (int y = 0; y < linear.height; ++y) {
                const std::uint8_t* src = out.srgb8.data() + size_t(y + margin) * ext_row + size_t(margin) * 3;
                std::copy(src, src + row, result.srgb8.data() + size_t(y) * row);
            }
        }
        report.glare_ms = plan_ms + out.glare_ms;
        report.tone_ms = out.tone_ms;
        return result;
    }
    std::string method;
    const Image glared = apply_glare_plan(linear, plan, threads, &method);
    report.glare = settings.glare.enabled && method == "off" ? "skipped" : method;
    report.glare_ms = elapsed_ms(start);
    start = std::chrono::steady_clock::now();
    DisplaySettings manual = settings;
    manual.exposure_mode = ExposureMode::manual;
    manual.exposure = report.exposure;
    result.srgb8 = apply_display(glared, manual, threads);
    report.tone_ms = elapsed_ms(start);
    return result;
}

DisplayImage display_image(const Image& linear, const DisplaySettings& settings, double fov_y_degrees, int threads) {
    return run_display_stage(linear, settings, fov_y_degrees, threads, nullptr);
}

}  // namespace airlight
