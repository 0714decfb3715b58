// The phase function's part of the frame: the medium's lobes as the shaders
// read them, and the per-lobe tables with the culling bounds they give.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "frame_data.hpp"
#include "lamp_frame.hpp"
#include "phase_tables.hpp"
#include "spot_frame.hpp"

namespace airlight {
namespace {

// The per-lobe tables sit in consecutive slots (effects/phase/effect.cmake).
static_assert(shader::TABLE_PHASE_MOMENTS_1 == shader::TABLE_PHASE_MOMENTS_0 + 1 &&
              shader::TABLE_PHASE_GLOW_1 == shader::TABLE_PHASE_GLOW_0 + 1);

// The lobes of an anisotropic phase function with their weights (none for an
// isotropic medium, or an HG one with g = 0: the isotropic tables are exact
// there). |g| is clamped to PHASE_G_LIMIT.
std::vector<std::pair<PhaseLobe, float>> phase_lobes(const Phase& phase) {
    auto hg = [](float g) {
        PhaseLobe l;
        l.g = std::clamp(g, -shader::PHASE_G_LIMIT, shader::PHASE_G_LIMIT);
        return l;
    };
    std::vector<std::pair<PhaseLobe, float>> lobes;
    switch (phase.type) {
        case PhaseType::isotropic:
            break;
        case PhaseType::hg:
            if (phase.g != 0.0f) lobes.push_back({hg(phase.g), 1.0f});
            break;
        case PhaseType::rayleigh: {
            PhaseLobe l;
            l.rayleigh = true;
            lobes.push_back({l, 1.0f});
            break;
        }
        case PhaseType::hg2:
            if (phase.forward_g == 0.0f && phase.backward_g == 0.0f) break;
            if (phase.forward_weight > 0.0f) lobes.push_back({hg(phase.forward_g), phase.forward_weight});
            if (phase.forward_weight < 1.0f) lobes.push_back({hg(phase.backward_g), 1.0f - phase.forward_weight});
            break;
    }
    return lobes;
}

std::vector<std::pair<PhaseLobe, float>> scene_lobes(const Scene& scene, const FrameData& data) {
    return data.scattering ? phase_lobes(scene.medium.phase) : std::vector<std::pair<PhaseLobe, float>>{};
}

}  // namespace

void pack_phase_frame(const Scene& scene, FrameData& data) {
    shader::FrameUniforms& f = data.frame;
    const auto lobes = scene_lobes(scene, data);
    data.features.phase = !lobes.empty();
    f.phase.lobe_count = int(lobes.size());
    for (size_t i = 0; i < lobes.size(); ++i)
        (i == 0 ? f.phase.lobe0 : f.phase.lobe1) = phase_lobe_gpu(lobes[i].first, lobes[i].second);
    // The culling bounds of an isotropic medium (effects/lamp_airlight/docs/culling.md).
    f.phase.airlight_bound = 0.5f * shader::PI;
    f.phase.glow_bound = shader::SURFACE_GLOW_G_BOUND;
}

void pick_phase_tables(const Scene& scene, FrameData& data) {
    if (!data.features.phase) return;
    const auto lobes = scene_lobes(scene, data);
    const bool moments = needs_spot_moments(data) || needs_airlight_tail(data), glow = needs_surface_glow(data);
    double airlight_bound = 0.0, glow_bound = 0.0;
    for (size_t i = 0; i < lobes.size(); ++i) {
        const auto& [lobe, weight] = lobes[i];
        airlight_bound += weight * phase_airlight_bound(lobe);
        if (moments) data.use_table(shader::TABLE_PHASE_MOMENTS_0 + int(i), phase_moment_table(lobe));
        if (glow) data.use_table(shader::TABLE_PHASE_GLOW_0 + int(i), phase_glow_table(lobe));
        // The glow culling bound (a spot's glow is at most a lamp's): the
        // slice's maximum of G (for g < 0 above the isotropic 8.08: 63 at
        // g = -0.9); without a slice (spots only) G <= 2 pi^2 int_0^{pi/2} P dt,
        // from Q_p(u, xi) <= int_xi^{pi/2} P dt and Phi <= 2 pi.
        const double pi = double(shader::PI);
        const Table2D* slice = data.tables[size_t(shader::TABLE_PHASE_GLOW_0) + i];
        glow_bound += weight * (slice ? std::exp(double(*std::max_element(slice->texels.begin(), slice->texels.end())))
                                      : 2.0 * pi * pi * phase_airlight_bound(lobe));
    }
    data.frame.phase.airlight_bound = float(airlight_bound * 1.0001);
    data.frame.phase.glow_bound = float(glow_bound * 1.001);
}

}  // namespace airlight
