// The photo effect's part of the frame: the backplate as table TABLE_PHOTO,
// made for this frame only, and the atmospheric light.
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>

#include "frame_data.hpp"

namespace airlight {

void pack_photo_frame(const Scene& scene, FrameData& data) {
    shader::PhotoGpu& p = data.frame.photo;
    p.atmospheric_light = glm::vec4(scene.atmospheric_light, 0.0f);
    data.features.atmospheric_light =
        data.features.medium && glm::any(glm::greaterThan(scene.atmospheric_light, glm::vec3(0.0f)));
    const Backplate& b = scene.backplate;
    if (!b.rgbd) return;
    if (b.width != scene.film.width || b.height != scene.film.height ||
        b.rgbd->size() != size_t(b.width) * size_t(b.height) * 4)
        throw std::invalid_argument("backplate: " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                                    " does not match the film's " + std::to_string(scene.film.width) + "x" +
                                    std::to_string(scene.film.height));
    auto table = std::make_shared<Table2D>();
    table->name = "photo";
    table->width = b.width;
    table->height = b.height;
    table->channels = 4;
    table->texels = *b.rgbd;
    // An infinite depth (the ray escapes) as the shader's NO_HIT: no Inf reaches the GPU.
    for (size_t i = 3; i < table->texels.size(); i += 4)
        if (!(table->texels[i] < shader::NO_HIT)) table->texels[i] = shader::NO_HIT;
    table->serial = next_table_serial();  // a new texture each frame (gl_backend.cpp's cache)
    data.use_table(shader::TABLE_PHOTO, std::move(table));
    p.intrinsics = glm::vec4(b.intrinsics[0], b.intrinsics[1], b.intrinsics[2], b.intrinsics[3]);
    p.depth_along_axis = b.depth_along_axis ? 1 : 0;
    data.features.photo = true;
}

}  // namespace airlight
