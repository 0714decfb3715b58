# The rainbow's spectral table is assembled into the library (rainbow_data.cpp).
set(AIRLIGHT_RAINBOW_DATA ${CMAKE_CURRENT_SOURCE_DIR}/effects/rainbow/rainbow_phase.bin)
set_source_files_properties(effects/rainbow/rainbow_data.cpp PROPERTIES
  COMPILE_DEFINITIONS "AIRLIGHT_RAINBOW_DATA=\"${AIRLIGHT_RAINBOW_DATA}\""
  OBJECT_DEPENDS ${AIRLIGHT_RAINBOW_DATA})
if(AIRLIGHT_BUILD_TESTS AND NOT SKBUILD)
  # The spectral table's generator: run by hand, its output rainbow_phase.bin
  # is committed and embedded into the library.
  add_executable(make_rainbow_table effects/rainbow/make_rainbow_table.cpp effects/rainbow/mie.cpp
                                    effects/rainbow/rainbow.cpp)
  target_include_directories(make_rainbow_table PRIVATE ${AIRLIGHT_INCLUDE_DIRS})
  target_link_libraries(make_rainbow_table PRIVATE glm::glm Threads::Threads)
  target_compile_options(make_rainbow_table PRIVATE ${AIRLIGHT_WARNINGS} -O3 -march=native)
endif()
