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

#include "layout.glsl"

// Which optional features a scene uses; a GL shader variant is compiled per
// combination, the CPU backend branches on them at run time.
struct Features {
    bool medium = false;
    bool point_lights = false;
    bool surfaces = false;

    int key() const { return (medium ? 1 : 0) | (point_lights ? 2 : 0) | (surfaces ? 4 : 0); }
};

}  // namespace airlight::shader
