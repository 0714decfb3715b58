# Daytime: CIE skies, the sun and a height-varying atmosphere of molecules,
# aerosol and rain (physics.md; effects/daytime/docs/daytime.md).
set(EFFECT_SOURCES sky.cpp daytime_keys.cpp daytime_frame.cpp)
set(EFFECT_SCENE_KEYS sky sun atmosphere)
set(EFFECT_GLSL_MATH sky_math.glsl)
set(EFFECT_GLSL_PIXEL sky.glsl aerial_table.glsl)
set(EFFECT_FEATURES
    sky=HAS_SKY                # a sky dome: seen by escaping rays, lights surfaces
    sun=HAS_SUN                # a sun above the horizon with some irradiance
    atmosphere=HAS_ATMOSPHERE  # a height-varying atmosphere: scattering volumes along view rays
    sky_march=SKY_MARCH        # brute-force marching of the atmosphere instead (benchmarks)
    aerial_table=HAS_AERIAL_TABLE)  # camera rays look the atmosphere up in the aerial table (aerial_table.glsl)
set(EFFECT_TABLES
    sky_phase                 # F_k(C, d): the sky dome through each species' phase function
    aerial_segments           # per elevation row: each segment's optical depth, sun, medium sun, residual beam
    aerial_diffuse_segments   # per elevation row and azimuth block: each segment's diffuse light
    aerial                    # the same summed from the camera to each distance node
    aerial_diffuse)
set(EFFECT_PASSES aerial_segments aerial_diffuse_segments aerial aerial_diffuse)  # in this order
set(EFFECT_FRAME 1)
set(EFFECT_GLSL_LAYOUT daytime_layout.glsl)
set(EFFECT_UNIFORMS
    "SkyGpu sky"
    "SpeciesGpu species[SPECIES_COUNT]"  # SPECIES_MOLECULES, SPECIES_AEROSOL, SPECIES_RAIN (phase.z = 0 when absent)
    "AtmosphereGpu atmosphere"
    "AerialGpu aerial")
set(EFFECT_GLSL_TERMS daytime_terms.glsl)
set(EFFECT_HOOKS
    surface_irradiance=sky_surface_irradiance
    surface_irradiance=sun_surface_irradiance
    escaping_radiance=sky_escaping_radiance
    view_transfer=atmosphere_view_transfer)
set(EFFECT_LAYERS
    "sky=the sky dome's and the sun's light scattered toward the camera by the atmosphere (molecules, aerosol, rain: every order where multiple scattering is on), but for the rainbow's part")
set(EFFECT_SCENE_HEADER daytime_scene.hpp)
set(EFFECT_SCENE_MEMBERS "Sky sky" "Sun sun" "Atmosphere atmosphere")
set(EFFECT_QUALITY DaytimeQuality)
set(EFFECT_QUALITY_KEYS sky_segments aerial_table)
