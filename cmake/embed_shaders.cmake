# Writes OUTPUT: a C++ file defining airlight::shader_source(name) that returns
# the text of each file in SHADERS (a |-separated list of paths), as raw string literals.
set(body "#include \"shader_sources.hpp\"\n#include <map>\n#include <stdexcept>\n\nnamespace airlight {\n\nconst std::string& shader_source(const std::string& name) {\n    static const std::map<std::string, std::string> sources = {\n")
string(REPLACE "|" ";" SHADERS "${SHADERS}")
foreach(path IN LISTS SHADERS)
    get_filename_component(name "${path}" NAME)
    file(READ "${path}" text)
    string(APPEND body "        {\"${name}\", R\"airlight_glsl(${text})airlight_glsl\"},\n")
endforeach()
string(APPEND body "    };\n    auto it = sources.find(name);\n    if (it == sources.end()) throw std::out_of_range(\"airlight: no shader named \" + name);\n    return it->second;\n}\n\n}  // namespace airlight\n")
file(WRITE "${OUTPUT}.tmp" "${body}")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
