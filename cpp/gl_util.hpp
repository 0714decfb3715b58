// GL helpers shared by the core GL backend (cpp/gl_backend.cpp) and the
// effects' GL passes (EFFECT_GL_SOURCES, e.g. effects/display/display_gl.cpp):
// the GL 4.5 core headers, shader compilation and linking, buffer and texture
// allocation, uniforms, timing. Built only with the GL backend (cpp/gl_util.cpp).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#include <chrono>
#include <cstddef>
#include <initializer_list>
#include <string>

namespace airlight {
namespace gl {

// The first lines of every GLSL source: version and the macros that let the
// shared GLSL compile as C++ too (cpp/shader_cpp.hpp).
inline constexpr const char kGlslPrelude[] =
    "#version 450 core\n"
    "#define CONST const\n"
    "#define OUT(T) out T\n"
    "#define INOUT(T) inout T\n"
    "#define INLINE\n"
    "#define PRECISE precise\n"
    "#define DECLARE(signature) signature;\n";

// A compiled shader of `stage`; throws std::runtime_error with the log on failure.
GLuint compile_shader(GLenum stage, const std::string& source);

// Links the compiled `stages` into a program (the stages are deleted).
GLuint link_stages(std::initializer_list<GLuint> stages);

GLuint link_program(const std::string& vertex, const std::string& fragment);

// A compute program from one source (display and glare passes).
GLuint link_compute_program(const std::string& source);

// Uploads `bytes` into a buffer object, growing it when needed. Storage
// buffers are never empty (GL forbids binding a zero-sized range).
void upload(GLuint buffer, GLenum target, const void* bytes, size_t size, size_t& capacity);

// Grows a buffer object to at least `bytes` (contents are not kept).
void ensure_buffer(GLuint buffer, size_t bytes, size_t& capacity);

// A 2-D texture of `format`, re-created when the size changes.
void ensure_texture(GLuint& tex, int& tex_w, int& tex_h, GLenum format, int w, int h);

// Sets a uniform of `program` by name (optimised-out uniforms are ignored).
void set_uniform(GLuint program, const char* name, int v);
void set_uniform(GLuint program, const char* name, float v);

// log2 of the power of two `p`.
int log2_of_pow2(int p);

double ms_since(std::chrono::steady_clock::time_point t0);

}  // namespace gl
}  // namespace airlight
