# The effects, one line each. The order is the order their GLSL is compiled
# in (an effect may call the functions of those above it) and the order their
# features, tables and frame data are declared. Adding an effect: create its
# folder with an effect.cmake (cmake/effects.cmake says what it sets), then add
# its line here.
airlight_effect(light_shafts)
airlight_effect(lamp_airlight)
airlight_effect(phase)
airlight_effect(spotlights)
airlight_effect(rainbow)
airlight_effect(multiple_scattering)
airlight_effect(photo)
airlight_effect(daytime)
airlight_effect(noise_clouds)
airlight_effect(particle_clouds)
airlight_effect(sun_shadow_map)
airlight_effect(falling_rain)
airlight_effect(display)
