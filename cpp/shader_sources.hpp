// The GLSL files of shaders/, embedded into the library at build time
// (cmake/embed_shaders.cmake), so installed binaries need no shader files.
#pragma once

#include <string>

namespace airlight {

// Text of shaders/<name>; throws std::out_of_range for an unknown name.
const std::string& shader_source(const std::string& name);

}  // namespace airlight
