// Compiles the shared GLSL formulas (the core's and every effect's
// EFFECT_GLSL_MATH files, in registry order) as C++ against GLM: the one
// source of truth for the math used by both backends. The GL side defines the
// same qualifier macros in its shader prelude (cpp/gl_util.hpp).
#pragma once

#include <glm/glm.hpp>

#include "airlight_registry.hpp"

namespace airlight::shader {

using namespace glm;

// GLSL qualifiers in a form both languages accept.
#define CONST static constexpr
#define OUT(T) T&
#define INOUT(T) T&

#define INLINE inline
// GLSL's `precise`: no contraction of a product and a sum into one fused multiply-add, so that the GPU rounds
// as the CPU build does (which targets x86-64 without FMA instructions).
#define PRECISE
// A function's prototype, for a call that comes before the function in the shared GLSL's order
// (GLSL needs it; C++ member functions see each other without one).
#define DECLARE(signature)

#include "airlight_glsl_math.inc"

// Which optional features a scene uses (AIRLIGHT_FEATURES, from the effects'
// EFFECT_FEATURES): a GL shader variant is compiled per combination, the CPU
// backend branches on them at run time.
struct Features {
#define AIRLIGHT_X(name, macro) bool name = false;
    AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X

    // A distinct integer per combination (the GL program cache's key).
    unsigned long long key() const {
        unsigned long long k = 0, bit = 1;
#define AIRLIGHT_X(name, macro) \
    k |= name ? bit : 0;        \
    bit <<= 1;
        AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X
        return k;
    }
};

}  // namespace airlight::shader
