# The effect registry's machinery (effects/registry.cmake lists the effects).
#
# airlight_effect(<name>) reads effects/<name>/effect.cmake, which sets:
#   EFFECT_SOURCES     C++ sources of the library (relative to the folder)
#   EFFECT_GL_SOURCES  C++ sources built only with the GL backend (its GL passes)
#   EFFECT_GLSL_MATH   GLSL formulas shared by every GL program and compiled as
#                      C++ in namespace airlight::shader (cpp/shader_cpp.hpp)
#   EFFECT_GLSL_LAYOUT GLSL structs of the effect's frame data (std140-safe:
#                      4-byte scalars in groups of four, vec4, ivec4), compiled
#                      after the core's constants and before its FrameUniforms
#   EFFECT_UNIFORMS    the effect's members of FrameUniforms, each "Type name"
#                      (a struct of its EFFECT_GLSL_LAYOUT; "Type name[N]" for
#                      an array): the shading pass reads frame.<name>, the C++
#                      side fills FrameData::uniforms.<name>
#   EFFECT_GLSL_PIXEL  GLSL functions of the per-pixel shading pass
#   EFFECT_GLSL_TERMS  GLSL functions compiled after every effect's
#                      EFFECT_GLSL_PIXEL (they may call any effect's): the
#                      functions its hooks name
#   EFFECT_HOOKS       the effect's terms in the integrator (shaders/shading.glsl),
#                      each kind=function; the generated airlight_hooks.glsl
#                      calls them in registry order. The kinds and signatures:
#                      surface_irradiance  vec3 f(vec3 p, vec3 n, int self, vec3 so_far):
#                                          irradiance on a surface point, summed
#                      escaping_radiance   vec3 f(vec3 dir): radiance of a ray
#                                          that meets nothing, summed onto background
#                      emitter_hit         void f(vec3 origin, vec3 dir, INOUT(float) t_hit,
#                                          INOUT(vec3) emitted, INOUT(bool) hit): an emitter
#                                          nearer than t_hit sets t_hit, emitted, hit
#                      view_transfer       vec3 f(vec3 origin, vec3 dir, float t_hit, vec3 radiance):
#                                          a medium along the view ray [0, t_hit]
#                                          attenuating `radiance` and adding its light
#                      view_glow           same signature, after every view_transfer:
#                                          light scattered toward the camera added
#                                          to `radiance` (which also serves culling)
#                      pixel_cores         vec3 f(int x, int row, vec3 radiance):
#                                          the pixel's radiance with sub-pixel
#                                          emitters composited over it
#                      backplate           bool f(int x, int row, INOUT(vec3) dir,
#                                          INOUT(float) t_end, INOUT(vec3) radiance):
#                                          true when pixel (x, row)'s ray (dir, which
#                                          it may replace) ends at t_end with that
#                                          radiance (an image: a photo and its depth)
#                                          in place of the surfaces, emitters and
#                                          cores; the first that returns true wins
#   EFFECT_FEATURES    shader switches, each name=MACRO: a bool of
#                      shader::Features and a compile-time constant MACRO in
#                      the GL variant / a member of the CPU shader
#   EFFECT_TABLES      tables the shading pass reads: each a slot of
#                      FrameData::tables, the GLSL/C++ constant TABLE_<NAME>
#                      (its index; the GL sampler binding) for the texel
#                      accessor table_texel4(TABLE_<NAME>, x, y)
#   EFFECT_SCENE_HEADER a header of the effect's scene data types (included by
#                      include/airlight/scene.hpp through the generated
#                      airlight_scene_parts.hpp)
#   EFFECT_SCENE_MEMBERS the effect's members of Scene, each "Type name"
#   EFFECT_QUALITY     the effect's struct of settings in the scene's "quality"
#                      object (a base of Quality, so its fields read
#                      scene.quality.<field>); its keys EFFECT_QUALITY_KEYS are
#                      parsed by parse_<name>_quality(const SceneObject&, Scene&)
#                      and written by write_<name>_quality(const Scene&, json&);
#                      preset_<name>_quality(QualityPreset, Scene&) sets them
#                      for the key quality.preset before the explicit keys
#   EFFECT_SCENE_KEYS  top-level scene keys the effect parses and writes back:
#                      it defines parse_<name>_keys(const SceneObject&, Scene&)
#                      and write_<name>_keys(const Scene&, nlohmann::json&)
#                      (cpp/scene_keys.hpp)
#   EFFECT_FRAME       1 when the effect fills its part of the frame: it
#                      defines pack_<name>_frame(const Scene&, FrameData&),
#                      called in registry order after the core's part, and
#                      may define pick_<name>_tables(const Scene&, FrameData&),
#                      called after every effect's pack (EFFECT_FRAME_TABLES 1),
#                      when its tables depend on other effects' features
#   EFFECT_LAYERS      the effect's layers of the render outputs (README "Render
#                      outputs"), each "name=what it holds" (no semicolons): parts
#                      of the radiance that sum to it; the GLSL constant
#                      LAYER_<NAME> (its index) for layer_add and friends
#                      (shaders/outputs.glsl), the output named <name>
#   EFFECT_PASSES      grid passes run before the shading pass, each named as
#                      one of its EFFECT_TABLES: the GLSL function
#                      vec4 <name>_pass(int x, int y) evaluated over a grid
#                      (FrameData::grid_passes says its size) by both
#                      backends fills that table, which the shading pass then
#                      reads like any other
# and may hold other files (shaders of its own passes, tests/, docs/,
# bench/). The core declares its own part the same way (cpp/core.cmake).
# airlight_write_registry() then writes generated/airlight_registry.hpp (the
# one list of features, tables and GLSL files in order, which the backends
# expand: no list is written by hand anywhere else) and
# generated/airlight_registry.glsl (the table constants, the first formula file).

set(AIRLIGHT_EFFECT_NAMES "")
set(AIRLIGHT_EFFECT_SOURCES "")
set(AIRLIGHT_EFFECT_GL_SOURCES "")
set(AIRLIGHT_EFFECT_DIRS "")
set(AIRLIGHT_GLSL_MATH "")
set(AIRLIGHT_GLSL_PIXEL "")
set(AIRLIGHT_GLSL_LAYOUT "")
set(AIRLIGHT_GLSL_TERMS "")
set(AIRLIGHT_UNIFORM_LIST "")
set(AIRLIGHT_SCENE_HEADERS "")
set(AIRLIGHT_SCENE_MEMBER_LIST "")
set(AIRLIGHT_QUALITY_BASES "")
set(AIRLIGHT_QUALITY_KEY_EFFECTS "")
set(AIRLIGHT_QUALITY_KEYS "")
set(AIRLIGHT_HOOK_KINDS surface_irradiance escaping_radiance emitter_hit view_transfer view_glow pixel_cores backplate)
foreach(kind IN LISTS AIRLIGHT_HOOK_KINDS)
  set(AIRLIGHT_HOOKS_${kind} "")
endforeach()
set(AIRLIGHT_FEATURE_LIST "")
set(AIRLIGHT_TABLE_LIST "")
set(AIRLIGHT_SCENE_KEY_EFFECTS "")
set(AIRLIGHT_SCENE_KEYS "")
set(AIRLIGHT_FRAME_EFFECTS "")
set(AIRLIGHT_FRAME_TABLE_EFFECTS "")
set(AIRLIGHT_PASS_LIST "")
set(AIRLIGHT_LAYER_LIST "")

macro(airlight_declare declaration dir name)
  set(EFFECT_SOURCES "")
  set(EFFECT_GL_SOURCES "")
  set(EFFECT_GLSL_MATH "")
  set(EFFECT_GLSL_PIXEL "")
  set(EFFECT_GLSL_LAYOUT "")
  set(EFFECT_UNIFORMS "")
  set(EFFECT_SCENE_HEADER "")
  set(EFFECT_SCENE_MEMBERS "")
  set(EFFECT_QUALITY "")
  set(EFFECT_QUALITY_KEYS "")
  set(EFFECT_GLSL_TERMS "")
  set(EFFECT_HOOKS "")
  set(EFFECT_FEATURES "")
  set(EFFECT_TABLES "")
  set(EFFECT_SCENE_KEYS "")
  set(EFFECT_FRAME 0)
  set(EFFECT_FRAME_TABLES 0)
  set(EFFECT_PASSES "")
  set(EFFECT_LAYERS "")
  include(${declaration})
  list(APPEND AIRLIGHT_EFFECT_NAMES ${name})
  list(APPEND AIRLIGHT_EFFECT_DIRS ${dir})
  foreach(s IN LISTS EFFECT_SOURCES)
    list(APPEND AIRLIGHT_EFFECT_SOURCES ${dir}/${s})
  endforeach()
  foreach(s IN LISTS EFFECT_GL_SOURCES)
    list(APPEND AIRLIGHT_EFFECT_GL_SOURCES ${dir}/${s})
  endforeach()
  if("${name}" STREQUAL "core")
    set(AIRLIGHT_CORE_GLSL_MATH ${EFFECT_GLSL_MATH})  # before the effects' layouts (frame.glsl after them)
  else()
    list(APPEND AIRLIGHT_GLSL_MATH ${EFFECT_GLSL_MATH})
  endif()
  list(APPEND AIRLIGHT_GLSL_PIXEL ${EFFECT_GLSL_PIXEL})
  list(APPEND AIRLIGHT_GLSL_LAYOUT ${EFFECT_GLSL_LAYOUT})
  list(APPEND AIRLIGHT_GLSL_TERMS ${EFFECT_GLSL_TERMS})
  list(APPEND AIRLIGHT_UNIFORM_LIST ${EFFECT_UNIFORMS})
  list(APPEND AIRLIGHT_SCENE_HEADERS ${EFFECT_SCENE_HEADER})
  list(APPEND AIRLIGHT_SCENE_MEMBER_LIST ${EFFECT_SCENE_MEMBERS})
  list(APPEND AIRLIGHT_QUALITY_BASES ${EFFECT_QUALITY})
  if(EFFECT_QUALITY_KEYS)
    list(APPEND AIRLIGHT_QUALITY_KEY_EFFECTS ${name})
    list(APPEND AIRLIGHT_QUALITY_KEYS ${EFFECT_QUALITY_KEYS})
  endif()
  foreach(hook IN LISTS EFFECT_HOOKS)
    string(REPLACE "=" ";" pair "${hook}")
    list(GET pair 0 kind)
    list(GET pair 1 function)
    if(NOT kind IN_LIST AIRLIGHT_HOOK_KINDS)
      message(FATAL_ERROR "effect ${name}: unknown hook kind ${kind} (cmake/effects.cmake lists them)")
    endif()
    list(APPEND AIRLIGHT_HOOKS_${kind} ${function})
  endforeach()
  list(APPEND AIRLIGHT_FEATURE_LIST ${EFFECT_FEATURES})
  list(APPEND AIRLIGHT_TABLE_LIST ${EFFECT_TABLES})
  foreach(layer IN LISTS EFFECT_LAYERS)
    if(NOT layer MATCHES "^[a-z][a-z0-9_]*=.+")
      message(FATAL_ERROR "effect ${name}: layer '${layer}' is not name=description")
    endif()
    list(APPEND AIRLIGHT_LAYER_LIST "${layer}")
  endforeach()
  if(EFFECT_SCENE_KEYS)
    list(APPEND AIRLIGHT_SCENE_KEY_EFFECTS ${name})
    list(APPEND AIRLIGHT_SCENE_KEYS ${EFFECT_SCENE_KEYS})
  endif()
  if(EFFECT_FRAME)
    list(APPEND AIRLIGHT_FRAME_EFFECTS ${name})
  endif()
  if(EFFECT_FRAME_TABLES)
    list(APPEND AIRLIGHT_FRAME_TABLE_EFFECTS ${name})
  endif()
  foreach(pass IN LISTS EFFECT_PASSES)
    if(NOT pass IN_LIST EFFECT_TABLES)
      message(FATAL_ERROR "effect ${name}: pass ${pass} is not one of its EFFECT_TABLES")
    endif()
    list(APPEND AIRLIGHT_PASS_LIST ${pass})
  endforeach()
endmacro()

macro(airlight_effect name)
  airlight_declare(${CMAKE_CURRENT_SOURCE_DIR}/effects/${name}/effect.cmake ${CMAKE_CURRENT_SOURCE_DIR}/effects/${name} ${name})
endmacro()

function(airlight_write_registry output)
  set(text "// Generated by cmake/effects.cmake from effects/registry.cmake and each\n")
  string(APPEND text "// effect's effect.cmake: do not edit.\n#pragma once\n\n")
  string(APPEND text "// The effects, in registry order.\n#define AIRLIGHT_EFFECT_NAMES \"${AIRLIGHT_EFFECT_NAMES}\"\n\n")
  string(APPEND text "// X(name, MACRO) for every shader switch.\n#define AIRLIGHT_FEATURES(X)")
  foreach(f IN LISTS AIRLIGHT_FEATURE_LIST)
    string(REPLACE "=" ";" pair "${f}")
    list(GET pair 0 fname)
    list(GET pair 1 fmacro)
    string(APPEND text " \\\n    X(${fname}, ${fmacro})")
  endforeach()
  string(APPEND text "\n\n// X(name) for every table the shading pass reads (its slot, sampler binding and accessor).\n")
  string(APPEND text "#define AIRLIGHT_TABLES(X)")
  foreach(t IN LISTS AIRLIGHT_TABLE_LIST)
    string(APPEND text " \\\n    X(${t})")
  endforeach()
  string(APPEND text "\n\n// X(effect) for every effect that parses top-level scene keys, and those keys.\n")
  string(APPEND text "#define AIRLIGHT_SCENE_KEY_EFFECTS(X)")
  foreach(e IN LISTS AIRLIGHT_SCENE_KEY_EFFECTS)
    string(APPEND text " \\\n    X(${e})")
  endforeach()
  string(APPEND text "\n#define AIRLIGHT_EFFECT_SCENE_KEYS")
  foreach(k IN LISTS AIRLIGHT_SCENE_KEYS)
    string(APPEND text " \"${k}\",")
  endforeach()
  string(APPEND text "\n\n// X(effect) for every effect that parses keys of the \"quality\" object, and those keys.\n")
  string(APPEND text "#define AIRLIGHT_QUALITY_KEY_EFFECTS(X)")
  foreach(e IN LISTS AIRLIGHT_QUALITY_KEY_EFFECTS)
    string(APPEND text " \\\n    X(${e})")
  endforeach()
  string(APPEND text "\n#define AIRLIGHT_EFFECT_QUALITY_KEYS")
  foreach(k IN LISTS AIRLIGHT_QUALITY_KEYS)
    string(APPEND text " \"${k}\",")
  endforeach()
  string(APPEND text "\n\n// X(effect) for every effect that fills its part of the frame, then those that pick tables after.\n")
  string(APPEND text "#define AIRLIGHT_FRAME_EFFECTS(X)")
  foreach(e IN LISTS AIRLIGHT_FRAME_EFFECTS)
    string(APPEND text " \\\n    X(${e})")
  endforeach()
  string(APPEND text "\n#define AIRLIGHT_FRAME_TABLE_EFFECTS(X)")
  foreach(e IN LISTS AIRLIGHT_FRAME_TABLE_EFFECTS)
    string(APPEND text " \\\n    X(${e})")
  endforeach()
  string(APPEND text "\n\n// X(name, TABLE_NAME) for every grid pass (run before the shading pass, fills that table).\n")
  string(APPEND text "#define AIRLIGHT_GRID_PASSES(X)")
  foreach(pass IN LISTS AIRLIGHT_PASS_LIST)
    string(TOUPPER "${pass}" upper)
    string(APPEND text " \\\n    X(${pass}, TABLE_${upper})")
  endforeach()
  string(APPEND text "\n\n// X(name, LAYER_NAME, description) for every layer of the render outputs (EFFECT_LAYERS).\n")
  string(APPEND text "#define AIRLIGHT_LAYERS(X)")
  foreach(layer IN LISTS AIRLIGHT_LAYER_LIST)
    string(FIND "${layer}" "=" eq)
    string(SUBSTRING "${layer}" 0 ${eq} lname)
    math(EXPR start "${eq} + 1")
    string(SUBSTRING "${layer}" ${start} -1 ldesc)
    string(REPLACE "\"" "\\\"" ldesc "${ldesc}")
    string(TOUPPER "${lname}" upper)
    string(APPEND text " \\\n    X(${lname}, LAYER_${upper}, \"${ldesc}\")")
  endforeach()
  set(glsl "// Generated by cmake/effects.cmake from the effects' EFFECT_TABLES and EFFECT_LAYERS: do not edit.\n")
  string(APPEND glsl "// The tables' slots: FrameData::tables index, GL sampler binding (resources.glsl).\n")
  set(index 0)
  foreach(t IN LISTS AIRLIGHT_TABLE_LIST)
    string(TOUPPER "${t}" upper)
    string(APPEND glsl "CONST int TABLE_${upper} = ${index};\n")
    math(EXPR index "${index} + 1")
  endforeach()
  string(APPEND glsl "CONST int TABLE_COUNT = ${index};\n")
  string(APPEND glsl "// The render outputs' layers: their index in PixelOutputs::layers (shaders/outputs.glsl).\n")
  set(index 0)
  foreach(layer IN LISTS AIRLIGHT_LAYER_LIST)
    string(FIND "${layer}" "=" eq)
    string(SUBSTRING "${layer}" 0 ${eq} lname)
    string(TOUPPER "${lname}" upper)
    string(APPEND glsl "CONST int LAYER_${upper} = ${index};\n")
    math(EXPR index "${index} + 1")
  endforeach()
  string(APPEND glsl "CONST int LAYER_COUNT = ${index};\n")
  string(APPEND glsl "\n// The effects' members of FrameUniforms (their EFFECT_UNIFORMS), in registry order.\n")
  string(APPEND glsl "#define AIRLIGHT_EFFECT_UNIFORMS")
  foreach(u IN LISTS AIRLIGHT_UNIFORM_LIST)
    string(APPEND glsl " \\\n    ${u};")
  endforeach()
  string(APPEND glsl "\n")
  get_filename_component(dir ${output} DIRECTORY)
  file(WRITE ${dir}/airlight_registry.glsl.tmp "${glsl}")
  file(COPY_FILE ${dir}/airlight_registry.glsl.tmp ${dir}/airlight_registry.glsl ONLY_IF_DIFFERENT)
  # The integrator's hooks (EFFECT_HOOKS): each kind's functions called in registry order.
  set(hooks "// Generated by cmake/effects.cmake from the effects' EFFECT_HOOKS: do not edit.\n")
  string(APPEND hooks "// The integrator (shading.glsl) calls these; each effect's function returns at once\n")
  string(APPEND hooks "// when its switches are off (compile-time constants in a GL variant).\n\n")
  string(APPEND hooks "vec3 hooks_surface_irradiance(vec3 p, vec3 n, int self) {\n    vec3 irradiance = vec3(0.0f);\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_surface_irradiance)
    string(APPEND hooks "    irradiance += ${f}(p, n, self, irradiance);\n")
  endforeach()
  string(APPEND hooks "    return irradiance;\n}\n\n")
  string(APPEND hooks "vec3 hooks_escaping_radiance(vec3 dir) {\n    vec3 radiance = vec3(0.0f);\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_escaping_radiance)
    string(APPEND hooks "    radiance += ${f}(dir);\n")
  endforeach()
  string(APPEND hooks "    return radiance;\n}\n\n")
  string(APPEND hooks "void hooks_emitter_hit(vec3 origin, vec3 dir, INOUT(float) t_hit, INOUT(vec3) emitted, INOUT(bool) hit) {\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_emitter_hit)
    string(APPEND hooks "    ${f}(origin, dir, t_hit, emitted, hit);\n")
  endforeach()
  string(APPEND hooks "}\n\n")
  string(APPEND hooks "vec3 hooks_view_segment(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_view_transfer AIRLIGHT_HOOKS_view_glow)
    string(APPEND hooks "    radiance = ${f}(origin, dir, t_hit, radiance);\n")
  endforeach()
  string(APPEND hooks "    return radiance;\n}\n\n")
  string(APPEND hooks "vec3 hooks_pixel_cores(int x, int row, vec3 radiance) {\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_pixel_cores)
    string(APPEND hooks "    radiance = ${f}(x, row, radiance);\n")
  endforeach()
  string(APPEND hooks "    return radiance;\n}\n\n")
  string(APPEND hooks "bool hooks_backplate(int x, int row, INOUT(vec3) dir, INOUT(float) t_end, INOUT(vec3) radiance) {\n")
  foreach(f IN LISTS AIRLIGHT_HOOKS_backplate)
    string(APPEND hooks "    if (${f}(x, row, dir, t_end, radiance)) return true;\n")
  endforeach()
  string(APPEND hooks "    return false;\n}\n")
  file(WRITE ${dir}/airlight_hooks.glsl.tmp "${hooks}")
  file(COPY_FILE ${dir}/airlight_hooks.glsl.tmp ${dir}/airlight_hooks.glsl ONLY_IF_DIFFERENT)
  # Compilation order: the registry's constants, the core's formulas, every
  # effect's layout, the frame (FrameUniforms), every effect's formulas; then
  # the core's and every effect's per-pixel functions, their terms, the hooks
  # and the integrator.
  set(math_order airlight_registry.glsl ${AIRLIGHT_CORE_GLSL_MATH} ${AIRLIGHT_GLSL_LAYOUT} ${AIRLIGHT_FRAME_GLSL}
      ${AIRLIGHT_GLSL_MATH})
  set(AIRLIGHT_GLSL_MATH ${math_order})
  list(APPEND AIRLIGHT_GLSL_PIXEL ${AIRLIGHT_GLSL_TERMS} airlight_hooks.glsl ${AIRLIGHT_INTEGRATOR_GLSL})
  string(APPEND text "\n\n// The GLSL files in compilation order: formulas, then the shading pass's functions.\n")
  string(APPEND text "#define AIRLIGHT_GLSL_MATH_FILES")
  foreach(g IN LISTS AIRLIGHT_GLSL_MATH)
    string(APPEND text " \"${g}\",")
  endforeach()
  string(APPEND text "\n#define AIRLIGHT_GLSL_PIXEL_FILES")
  foreach(g IN LISTS AIRLIGHT_GLSL_PIXEL)
    string(APPEND text " \"${g}\",")
  endforeach()
  string(APPEND text "\n")
  # The effects' scene data: their headers, their members of Scene, their quality settings.
  set(parts "// Generated by cmake/effects.cmake from the effects' EFFECT_SCENE_*: do not edit.\n#pragma once\n\n")
  foreach(h IN LISTS AIRLIGHT_SCENE_HEADERS)
    string(APPEND parts "#include \"${h}\"\n")
  endforeach()
  string(APPEND parts "\n// The effects' members of Scene (EFFECT_SCENE_MEMBERS), in registry order.\n")
  string(APPEND parts "#define AIRLIGHT_EFFECT_SCENE_MEMBERS")
  foreach(m IN LISTS AIRLIGHT_SCENE_MEMBER_LIST)
    string(APPEND parts " \\\n    ${m};")
  endforeach()
  string(APPEND parts "\n\n// The effects' quality settings (EFFECT_QUALITY): the bases of Quality after the core's.\n")
  string(APPEND parts "#define AIRLIGHT_EFFECT_QUALITY_BASES")
  foreach(b IN LISTS AIRLIGHT_QUALITY_BASES)
    string(APPEND parts " , public ${b}")
  endforeach()
  string(APPEND parts "\n")
  file(WRITE ${dir}/airlight_scene_parts.hpp.tmp "${parts}")
  file(COPY_FILE ${dir}/airlight_scene_parts.hpp.tmp ${dir}/airlight_scene_parts.hpp ONLY_IF_DIFFERENT)
  file(WRITE ${output}.tmp "${text}")
  file(COPY_FILE ${output}.tmp ${output} ONLY_IF_DIFFERENT)
  # The same files as #include lines, for the C++ compilation of the shared GLSL.
  set(math "// Generated by cmake/effects.cmake: do not edit.\n")
  foreach(g IN LISTS AIRLIGHT_GLSL_MATH)
    string(APPEND math "#include \"${g}\"\n")
  endforeach()
  set(pixel "// Generated by cmake/effects.cmake: do not edit.\n")
  foreach(g IN LISTS AIRLIGHT_GLSL_PIXEL)
    string(APPEND pixel "#include \"${g}\"\n")
  endforeach()
  file(WRITE ${dir}/airlight_glsl_math.inc.tmp "${math}")
  file(COPY_FILE ${dir}/airlight_glsl_math.inc.tmp ${dir}/airlight_glsl_math.inc ONLY_IF_DIFFERENT)
  file(WRITE ${dir}/airlight_glsl_pixel.inc.tmp "${pixel}")
  file(COPY_FILE ${dir}/airlight_glsl_pixel.inc.tmp ${dir}/airlight_glsl_pixel.inc ONLY_IF_DIFFERENT)
endfunction()
