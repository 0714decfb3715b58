// The render outputs beside the radiance (shaders/outputs_layout.glsl, README
// "Render outputs"): their list, and their unpacking from Image::outputs.
#include <limits>
#include <stdexcept>

#include "airlight/renderer.hpp"
#include "frame_data.hpp"

namespace airlight {

namespace {

// Where output `name` starts in a pixel's packed floats (-1: the radiance, in Image::rgb).
int output_offset(const std::string& name) {
    if (name == "radiance") return -1;
    if (name == "depth") return shader::OUTPUT_DEPTH;
    if (name == "distance_z") return shader::OUTPUT_DISTANCE_Z;
    if (name == "normal") return shader::OUTPUT_NORMAL;
    if (name == "transmittance") return shader::OUTPUT_TRANSMITTANCE;
#define AIRLIGHT_X(layer, index, description) \
    if (name == #layer) return shader::OUTPUT_LAYERS + 3 * shader::index;
    AIRLIGHT_LAYERS(AIRLIGHT_X)
#undef AIRLIGHT_X
    return -2;
}

}  // namespace

const std::vector<RenderOutput>& render_outputs() {
    static const std::vector<RenderOutput> outputs = [] {
        std::vector<RenderOutput> list = {
            {"radiance", 3, "linear radiance arriving at the camera, W/(m^2 sr): the sum of the layers", false},
            {"depth", 1,
             "distance (m) along the pixel's central ray to the first surface or light sphere it meets, "
             "+inf where it meets none",
             false},
            {"distance_z", 1,
             "the same distance along the camera's optical axis (m; depth times the cosine), +inf "
             "where the ray meets nothing",
             false},
            {"normal", 3,
             "unit world-space normal of the surface the ray meets, facing the camera; (0, 0, 0) on "
             "light spheres and where the ray meets nothing",
             false},
            {"transmittance", 3,
             "fraction of light passing from the ray's end (its surface, or the end of the "
             "atmosphere and medium where it meets nothing) to the camera, per channel",
             false},
        };
#define AIRLIGHT_X(layer, index, description) list.push_back({#layer, 3, description, true});
        AIRLIGHT_LAYERS(AIRLIGHT_X)
#undef AIRLIGHT_X
        return list;
    }();
    return outputs;
}

std::vector<float> output_values(const Image& image, const std::string& name) {
    const int offset = output_offset(name);
    if (offset == -2) throw std::invalid_argument("unknown render output '" + name + "'");
    if (offset == -1) return image.rgb;
    const size_t pixels = size_t(image.width) * size_t(image.height);
    if (image.output_floats != shader::OUTPUT_FLOATS || image.outputs.size() != pixels * size_t(image.output_floats))
        throw std::invalid_argument("render output '" + name + "': the image was rendered without its outputs");
    int components = 3;
    if (offset == shader::OUTPUT_DEPTH || offset == shader::OUTPUT_DISTANCE_Z) components = 1;
    std::vector<float> values(pixels * size_t(components));
    for (size_t p = 0; p < pixels; ++p) {
        const float* src = image.outputs.data() + p * size_t(image.output_floats) + size_t(offset);
        for (int c = 0; c < components; ++c) values[p * size_t(components) + size_t(c)] = src[c];
    }
    // The shaders' "no hit" distance (NO_HIT, finite in float32) is +inf here.
    if (components == 1)
        for (float& v : values)
            if (v >= shader::NO_HIT) v = std::numeric_limits<float>::infinity();
    return values;
}

}  // namespace airlight
