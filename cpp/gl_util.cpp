// GL helpers shared by the core GL backend and the effects' GL passes (gl_util.hpp).
#include "gl_util.hpp"

#include <algorithm>
#include <stdexcept>

namespace airlight {
namespace gl {

GLuint compile_shader(GLenum stage, const std::string& source) {
    GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetShaderInfoLog(shader, len, nullptr, log.data());
        glDeleteShader(shader);
        throw std::runtime_error("airlight: GLSL compilation failed (a bug in airlight): " + log);
    }
    return shader;
}

GLuint link_stages(std::initializer_list<GLuint> stages) {
    GLuint program = glCreateProgram();
    for (GLuint stage : stages) glAttachShader(program, stage);
    glLinkProgram(program);
    for (GLuint stage : stages) glDeleteShader(stage);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetProgramInfoLog(program, len, nullptr, log.data());
        glDeleteProgram(program);
        throw std::runtime_error("airlight: GLSL link failed (a bug in airlight): " + log);
    }
    return program;
}

GLuint link_program(const std::string& vertex, const std::string& fragment) {
    return link_stages({compile_shader(GL_VERTEX_SHADER, vertex), compile_shader(GL_FRAGMENT_SHADER, fragment)});
}

GLuint link_compute_program(const std::string& source) {
    return link_stages({compile_shader(GL_COMPUTE_SHADER, source)});
}

void upload(GLuint buffer, GLenum target, const void* bytes, size_t size, size_t& capacity) {
    const size_t needed = std::max<size_t>(size, 64);
    glBindBuffer(target, buffer);
    if (needed > capacity) {
        glBufferData(target, GLsizeiptr(needed), nullptr, GL_DYNAMIC_DRAW);
        capacity = needed;
    }
    if (size > 0) glBufferSubData(target, 0, GLsizeiptr(size), bytes);
}

void ensure_buffer(GLuint buffer, size_t bytes, size_t& capacity) {
    bytes = std::max<size_t>(bytes, 64);
    if (bytes <= capacity) return;
    glNamedBufferData(buffer, GLsizeiptr(bytes), nullptr, GL_DYNAMIC_COPY);
    capacity = bytes;
}

void ensure_texture(GLuint& tex, int& tex_w, int& tex_h, GLenum format, int w, int h) {
    if (tex != 0 && tex_w == w && tex_h == h) return;
    if (tex != 0) glDeleteTextures(1, &tex);
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, format, w, h);
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    tex_w = w;
    tex_h = h;
}

void set_uniform(GLuint program, const char* name, int v) {
    glProgramUniform1i(program, glGetUniformLocation(program, name), v);
}
void set_uniform(GLuint program, const char* name, float v) {
    glProgramUniform1f(program, glGetUniformLocation(program, name), v);
}

int log2_of_pow2(int p) {
    int l = 0;
    while ((1 << l) < p) ++l;
    return l;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace gl
}  // namespace airlight
