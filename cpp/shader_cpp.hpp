// Compiles the shared GLSL (shaders/*.glsl) as C++ against GLM: the one
// source of truth for per-pixel math used by both backends. The GLSL side
// defines the same macros in gl_backend.cpp's shader prelude.
#pragma once

#include <glm/glm.hpp>

namespace airlight::shader {

using namespace glm;

// GLSL qualifiers in a form both languages accept.
#define CONST static constexpr
#define OUT(T) T&
#define INOUT(T) T&

#define INLINE inline

#include "constants.glsl"
#include "layout.glsl"
#include "phase_math.glsl"
#include "sky_math.glsl"

// The display stage's per-pixel math (issue 8): independent of the above.
#include "display.glsl"

// Which optional features a scene uses; a GL shader variant is compiled per
// combination, the CPU backend branches on them at run time.
struct Features {
    bool medium = false;
    bool point_lights = false;
    bool surfaces = false;
    bool airlight = false;        // point lights in a scattering medium: airlight and surface glow
    bool airlight_march = false;  // brute-force ray marching instead of the tables (benchmarks)
    bool grey_medium = false;     // sigma_t and sigma_s equal on all channels: one evaluation, not three
    bool spot_lights = false;     // spotlights: direct light and cores
    bool spot_airlight = false;   // spotlights in a scattering medium
    bool phase = false;           // an anisotropic phase function (phase.glsl); else isotropic
    bool sky = false;             // a sky dome (sky.glsl): seen by escaping rays, lights surfaces
    bool sun = false;             // a sun above the horizon with some irradiance
    bool atmosphere = false;      // a height-varying atmosphere: scattering volumes along view rays
    bool sky_march = false;       // brute-force marching of the atmosphere instead (benchmarks)
    bool rainbow = false;         // rain lit by the sun scatters with the Mie table (rainbows)

    int key() const {
        return (medium ? 1 : 0) | (point_lights ? 2 : 0) | (surfaces ? 4 : 0) | (airlight ? 8 : 0) |
               (airlight_march ? 16 : 0) | (grey_medium ? 32 : 0) | (spot_lights ? 64 : 0) | (spot_airlight ? 128 : 0) |
               (phase ? 256 : 0) | (sky ? 512 : 0) | (sun ? 1024 : 0) | (atmosphere ? 2048 : 0) |
               (sky_march ? 4096 : 0) | (rainbow ? 8192 : 0);
    }
};

}  // namespace airlight::shader
