// airlight-demo --window: an interactive view (needs GLFW and a display).
// W/A/S/D move, Q/E down/up, arrow keys turn, +/- exposure, Esc quits. Each
// frame is rendered by a Renderer (GL or CPU backend), passed through the
// display stage (the scene's display settings: exposure, glare, tone curve)
// on the same backend, and shown as a texture.
#include "airlight/display.hpp"
#include "airlight/renderer.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace airlight {
namespace {

const char* kVertex = R"(#version 450 core
out vec2 uv;
void main() {
    vec2 c = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    uv = vec2(c.x, 1.0 - c.y);  // image row 0 is the top row
    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);
})";

const char* kFragment = R"(#version 450 core
in vec2 uv;
out vec4 color;
layout(binding = 0) uniform sampler2D image;
void main() { color = vec4(texture(image, uv).rgb, 1.0); })";

GLuint build_blit_program() {
    GLuint program = glCreateProgram();
    for (auto [stage, text] :
         {std::pair<GLenum, const char*>{GL_VERTEX_SHADER, kVertex}, {GL_FRAGMENT_SHADER, kFragment}}) {
        GLuint s = glCreateShader(stage);
        glShaderSource(s, 1, &text, nullptr);
        glCompileShader(s);
        glAttachShader(program, s);
        glDeleteShader(s);
    }
    glLinkProgram(program);
    return program;
}

}  // namespace

int run_window(Scene scene, Backend backend, DisplaySettings display) {
    if (!glfwInit()) throw std::runtime_error("cannot open a window (no display?)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    // EGL, like the GL backend: GLX and EGL contexts cannot take turns on one thread.
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    GLFWwindow* window = glfwCreateWindow(scene.film.width, scene.film.height, "airlight", nullptr, nullptr);
    if (window == nullptr) {
        glfwTerminate();
        throw std::runtime_error("cannot create a 4.5 core window");
    }
    Renderer renderer(backend);
    glfwMakeContextCurrent(window);
    GLuint program = build_blit_program();
    GLuint vao = 0, texture = 0;
    glCreateVertexArrays(1, &vao);

    glm::vec3 forward = glm::normalize(scene.camera.look_at - scene.camera.position);
    float yaw = std::atan2(forward.x, -forward.z);
    float pitch = std::asin(glm::clamp(forward.y, -1.0f, 1.0f));
    double last = glfwGetTime();
    int tex_w = 0, tex_h = 0;
    float shown_exposure = display.exposure;  // the exposure of the last frame shown
    while (!glfwWindowShouldClose(window)) {
        glfwPollEvents();
        const double now = glfwGetTime();
        const float dt = float(now - last);
        last = now;
        auto down = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS; };
        if (down(GLFW_KEY_ESCAPE)) break;
        yaw += dt * ((down(GLFW_KEY_RIGHT) ? 1.0f : 0.0f) - (down(GLFW_KEY_LEFT) ? 1.0f : 0.0f));
        pitch = glm::clamp(pitch + dt * ((down(GLFW_KEY_UP) ? 1.0f : 0.0f) - (down(GLFW_KEY_DOWN) ? 1.0f : 0.0f)),
                           -1.5f, 1.5f);
        forward = glm::vec3(std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
        const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
        const float speed = 10.0f * dt;
        glm::vec3& pos = scene.camera.position;
        pos += forward * speed * ((down(GLFW_KEY_W) ? 1.0f : 0.0f) - (down(GLFW_KEY_S) ? 1.0f : 0.0f));
        pos += right * speed * ((down(GLFW_KEY_D) ? 1.0f : 0.0f) - (down(GLFW_KEY_A) ? 1.0f : 0.0f));
        pos.y += speed * ((down(GLFW_KEY_E) ? 1.0f : 0.0f) - (down(GLFW_KEY_Q) ? 1.0f : 0.0f));
        if (down(GLFW_KEY_EQUAL) || down(GLFW_KEY_MINUS)) {
            // From automatic exposure, +/- start at the exposure it chose.
            display.exposure_mode = ExposureMode::manual;
            display.exposure = shown_exposure * (down(GLFW_KEY_EQUAL) ? 1.0f + dt : 1.0f / (1.0f + dt));
        }
        scene.camera.look_at = pos + forward;
        scene.camera.up = glm::vec3(0, 1, 0);

        const Image image = renderer.render(scene);
        const DisplayImage shown = renderer.display(image, display, scene.camera.fov_y_degrees);
        shown_exposure = shown.report.exposure;
        glfwMakeContextCurrent(window);  // the GL backend switches to its own context
        if (shown.width != tex_w || shown.height != tex_h) {
            if (texture != 0) glDeleteTextures(1, &texture);
            glCreateTextures(GL_TEXTURE_2D, 1, &texture);
            glTextureStorage2D(texture, 1, GL_RGB8, shown.width, shown.height);
            glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            tex_w = shown.width;
            tex_h = shown.height;
        }
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);  // rows of 3-byte pixels
        glTextureSubImage2D(texture, 0, 0, 0, shown.width, shown.height, GL_RGB, GL_UNSIGNED_BYTE, shown.srgb8.data());
        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(window, &fb_w, &fb_h);
        glViewport(0, 0, fb_w, fb_h);
        glUseProgram(program);
        glBindTextureUnit(0, texture);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glfwSwapBuffers(window);
    }
    glfwDestroyWindow(window);
    glfwTerminate();
    return 0;
}

}  // namespace airlight
