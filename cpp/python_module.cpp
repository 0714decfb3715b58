// airlight._core: the pybind11 bridge. Scenes arrive as Python objects and are
// converted to JSON values in C++ so that NaN/Inf survive to the validator;
// scene errors become TypeError/ValueError naming the field.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <future>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "airlight/display.hpp"
#include "airlight/glare.hpp"
#include "airlight/image_io.hpp"
#include "airlight/renderer.hpp"
#include "airlight/scene_io.hpp"
#include "airlight_tables.hpp"
#include "drop_optics.hpp"
#include "drops.hpp"
#include "frame_data.hpp"
#include "ms_tables.hpp"
#include "noise.hpp"
#include "numerics.hpp"
#include "particle_field.hpp"
#include "particle_table.hpp"
#include "phase_tables.hpp"
#include "plane_parallel.hpp"
#include "point_source.hpp"
#include "rainbow.hpp"
#include "scene_json.hpp"
#include "sky.hpp"
#include "sphere_scattering.hpp"
#include "spot_tables.hpp"
#include "tables.hpp"

namespace py = pybind11;
using airlight::Scene;

namespace {

// Python value -> JSON value. Unsupported types become a TypeError naming the
// path, so that e.g. a set inside the scene is reported, not crashed on.
std::string type_name_of(py::handle obj) { return py::str(py::type::of(obj).attr("__name__")); }

std::string field_name(const std::string& path) { return path.empty() ? std::string("scene") : path; }

// UTF-8 of a Python str; strings that cannot be encoded (lone surrogates)
// are a ValueError naming the field.
std::string utf8(py::handle obj, const std::string& path) {
    Py_ssize_t size = 0;
    const char* data = PyUnicode_AsUTF8AndSize(obj.ptr(), &size);
    if (data == nullptr) {
        PyErr_Clear();
        throw py::value_error(field_name(path) + ": string is not valid Unicode");
    }
    return std::string(data, size_t(size));
}

nlohmann::json to_json(py::handle obj, const std::string& path, int depth = 0) {
    if (depth > 64) throw py::value_error(field_name(path) + ": nesting too deep");
    if (obj.is_none()) return nullptr;
    if (py::isinstance<py::bool_>(obj)) return obj.cast<bool>();
    if (py::hasattr(obj, "dtype") && py::hasattr(obj, "ndim") && obj.attr("ndim").cast<int>() == 0) {
        // numpy scalars and 0-d arrays: their Python value (np.bool_ stays a bool).
        return to_json(obj.attr("item")(), path, depth + 1);
    }
    if (py::isinstance<py::int_>(obj)) {
        int overflow = 0;
        const long long value = PyLong_AsLongLongAndOverflow(obj.ptr(), &overflow);
        if (overflow == 0) return value;
        // Beyond 64 bits: an infinite number, which the validator rejects by name.
        return overflow > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    }
    if (py::isinstance<py::float_>(obj)) return obj.cast<double>();
    if (py::isinstance<py::str>(obj)) return utf8(obj, path);
    if (py::isinstance<py::dict>(obj)) {
        nlohmann::json out = nlohmann::json::object();
        for (auto item : py::reinterpret_borrow<py::dict>(obj)) {
            if (!py::isinstance<py::str>(item.first)) {
                throw py::type_error(field_name(path) + ": keys must be strings, got " + type_name_of(item.first));
            }
            const std::string key = utf8(item.first, path);
            out[key] = to_json(item.second, path.empty() ? key : path + "." + key, depth + 1);
        }
        return out;
    }
    if (py::isinstance<py::list>(obj) || py::isinstance<py::tuple>(obj) || py::isinstance<py::array>(obj)) {
        // Refused before it is converted: a list of 10^7 elements took 28 s and 670 MB to be rejected.
        constexpr size_t kMaxListLength = size_t(1) << 20;
        const size_t length = size_t(py::len(obj));
        if (length > kMaxListLength)
            throw py::value_error(field_name(path) + ": list too long (" + std::to_string(length) +
                                  " elements, at most " + std::to_string(kMaxListLength) + ")");
        py::sequence seq = py::isinstance<py::array>(obj) ? py::sequence(obj.attr("tolist")())
                                                          : py::reinterpret_borrow<py::sequence>(obj);
        nlohmann::json out = nlohmann::json::array();
        for (size_t i = 0; i < seq.size(); ++i) {
            out.push_back(to_json(seq[i], path + "[" + std::to_string(i) + "]", depth + 1));
        }
        return out;
    }
    throw py::type_error(field_name(path) + ": unsupported type " + type_name_of(obj));
}

// Renders on a worker thread while this (Python's) thread waits with the GIL
// released, checking for signals every 50 ms: Ctrl-C cancels the render
// (Renderer::render's cancel flag) and raises KeyboardInterrupt once the worker
// has stopped. Python runs signal handlers only on its main thread, which is
// why the render itself moves to a worker.
airlight::Image render_interruptibly(airlight::Renderer& renderer, const Scene& scene, bool with_outputs = false) {
    std::atomic<bool> cancel{false};
    std::promise<airlight::Image> result;
    std::future<airlight::Image> done = result.get_future();
    bool interrupted = false;
    {
        py::gil_scoped_release release;
        std::thread worker([&] {
            try {
                result.set_value(renderer.render(scene, &cancel, with_outputs));
            } catch (...) {
                result.set_exception(std::current_exception());
            }
        });
        while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
            if (interrupted) continue;
            py::gil_scoped_acquire acquire;
            if (PyErr_CheckSignals() != 0) {  // the KeyboardInterrupt (or other) is now set
                interrupted = true;
                cancel = true;
            }
        }
        worker.join();
    }
    if (interrupted) {
        try {
            done.get();
        } catch (const airlight::RenderCancelled&) {
        }
        throw py::error_already_set();
    }
    return done.get();
}

Scene scene_from_python(py::handle obj) {
    if (py::isinstance<py::str>(obj)) return airlight::parse_scene(obj.cast<std::string>());
    return airlight::parse_scene_json(to_json(obj, ""));
}

py::array_t<float> image_to_numpy(airlight::Image&& image) {
    auto* owned = new std::vector<float>(std::move(image.rgb));
    py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return py::array_t<float>({image.height, image.width, 3}, owned->data(), free_when_done);
}

// Display settings from the Python arguments (already type-checked by
// airlight.display); bad values are a ValueError naming the argument.
airlight::DisplaySettings display_settings(const std::optional<float>& exposure, const std::string& tonemap,
                                           const std::optional<float>& white) {
    airlight::DisplaySettings settings;
    try {
        settings.curve = airlight::tone_curve_from_name(tonemap, "tonemap");
        if (exposure) {
            settings.exposure_mode = airlight::ExposureMode::manual;
            settings.exposure = *exposure;
        }
        settings.white = white;
        airlight::validate_display_settings(settings, "");
    } catch (const std::invalid_argument& e) {
        throw py::value_error(e.what());
    }
    return settings;
}

airlight::Image image_from_numpy(const py::array_t<float, py::array::c_style | py::array::forcecast>& a) {
    if (a.ndim() != 3 || a.shape(2) != 3) throw py::value_error("radiance: expected shape (height, width, 3)");
    airlight::Image image;
    image.height = int(a.shape(0));
    image.width = int(a.shape(1));
    image.rgb.assign(a.data(), a.data() + a.size());
    return image;
}

// A failed file operation (std::runtime_error: the path and the library's
// reason) as Python's OSError; call with the GIL held.
[[noreturn]] void throw_os_error(const std::runtime_error& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
}

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// EXR images from Python: (name, float32 array of shape (height, width) or
// (height, width, 3)) pairs, all of one size (airlight._image_io checks the
// arguments first and names them; these checks are the last line).
std::vector<airlight::NamedImage> named_images_from_numpy(const std::vector<std::pair<std::string, FloatArray>>& images,
                                                          int& width, int& height) {
    std::vector<airlight::NamedImage> out;
    for (std::size_t i = 0; i < images.size(); ++i) {
        const auto& [name, a] = images[i];
        const std::string field = "images['" + name + "']";
        if (!(a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 3)))
            throw py::value_error(field + ": expected shape (height, width) or (height, width, 3)");
        if (i == 0) {
            if (a.shape(0) > std::numeric_limits<int>::max() || a.shape(1) > std::numeric_limits<int>::max())
                throw py::value_error(field + ": too large");
            height = int(a.shape(0));
            width = int(a.shape(1));
        } else if (a.shape(0) != height || a.shape(1) != width) {
            throw py::value_error(field + ": expected height " + std::to_string(height) + " and width " +
                                  std::to_string(width) + " as the first image's");
        }
        out.push_back({name, a.ndim() == 3 ? 3 : 1, std::vector<float>(a.data(), a.data() + a.size())});
    }
    return out;
}

// The multiple-scattering solver's result as numpy arrays
// (effects/multiple_scattering/plane_parallel.hpp names the fields).
py::dict field_to_python(const airlight::MultipleScatteringField& f) {
    const auto levels = py::ssize_t(f.altitudes.size());
    auto vec = [](const std::vector<double>& v) { return py::array_t<double>(py::ssize_t(v.size()), v.data()); };
    auto rgb = [&](const std::vector<airlight::RgbD>& v) {
        py::array_t<double> a({levels, py::ssize_t(3)});
        std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(airlight::RgbD));
        return a;
    };
    py::dict d;
    d["altitudes"] = vec(f.altitudes);
    d["column"] = rgb(f.column);
    d["view_mu"] = vec(f.view_mu);
    d["view_phi"] = vec(f.view_phi);
    d["node_mu"] = vec(f.node_mu);
    d["node_weight"] = vec(f.node_weight);
    py::array_t<double> phased({levels, py::ssize_t(f.species_count), py::ssize_t(3), py::ssize_t(f.view_mu.size()),
                                py::ssize_t(f.view_phi.size())});
    std::memcpy(phased.mutable_data(), f.phased_radiance.data(), f.phased_radiance.size() * sizeof(double));
    d["phased_radiance"] = phased;
    py::array_t<double> nodes(
        {levels, py::ssize_t(3), py::ssize_t(f.fourier_modes), py::ssize_t(2 * f.streams), py::ssize_t(2)});
    std::memcpy(nodes.mutable_data(), f.node_radiance.data(), f.node_radiance.size() * sizeof(double));
    d["node_radiance"] = nodes;
    d["irradiance_down"] = rgb(f.irradiance_down);
    d["irradiance_up"] = rgb(f.irradiance_up);
    d["sun_direct_irradiance"] = rgb(f.sun_direct_irradiance);
    d["sky_direct_irradiance"] = rgb(f.sky_direct_irradiance);
    d["sun_forward_irradiance"] = rgb(f.sun_forward_irradiance);
    py::array_t<double> sh({levels, py::ssize_t(3), py::ssize_t(9)});
    std::memcpy(sh.mutable_data(), f.radiance_sh.data(), f.radiance_sh.size() * sizeof(f.radiance_sh[0]));
    d["radiance_sh"] = sh;
    d["incident_flux"] = py::make_tuple(f.incident_flux[0], f.incident_flux[1], f.incident_flux[2]);
    d["streams"] = f.streams;
    d["modes_solved"] = f.modes_solved;
    d["sun_mu"] = f.sun_mu;
    d["solve_seconds"] = f.solve_seconds;
    return d;
}

airlight::SolverOptions solver_options(int streams, int max_fourier_mode, double initial_depth, bool delta_m,
                                       const std::vector<double>& view_mu, const std::vector<double>& view_phi,
                                       double azimuth_tolerance) {
    if (!(azimuth_tolerance >= 0.0 && azimuth_tolerance < 1.0))
        throw py::value_error("azimuth_tolerance: must be in [0, 1)");
    if (streams < 2 || streams > 128) throw py::value_error("streams: must be in [2, 128]");
    if (!(initial_depth > 0.0 && initial_depth <= 16.0)) throw py::value_error("initial_depth: must be in (0, 16]");
    for (double v : view_mu)
        if (!(v >= -1.0 && v <= 1.0)) throw py::value_error("view_mu: must be in [-1, 1]");
    for (double v : view_phi)
        if (!std::isfinite(v)) throw py::value_error("view_phi: must be finite");
    airlight::SolverOptions o;
    o.streams = streams;
    o.max_fourier_mode = max_fourier_mode;
    o.initial_depth = initial_depth;
    o.delta_m = delta_m;
    o.view_mu = view_mu;
    o.view_phi = view_phi;
    o.azimuth_tolerance = azimuth_tolerance;
    return o;
}

}  // namespace

// The particle clouds' solver grid (effects/particle_clouds/sphere_scattering.hpp) from a dict of
// its fields; a ValueError names a bad key or value.
airlight::SphereGrid parse_sphere_grid(const py::dict& keys) {
    airlight::SphereGrid grid;
    for (auto item : keys) {
        const std::string key = py::str(item.first);
        if (key == "beyond" || key == "graded_polar") {
            if (!py::isinstance<py::bool_>(item.second))
                throw py::type_error("grid." + key + ": must be true or false");
            (key == "beyond" ? grid.beyond : grid.graded_polar) = item.second.cast<bool>();
            continue;
        }
        if (key == "surface_step") {
            if (!py::isinstance<py::float_>(item.second) && !py::isinstance<py::int_>(item.second))
                throw py::type_error("grid.surface_step: must be a number");
            grid.surface_step = item.second.cast<double>();
            continue;
        }
        int* field = key == "radii"                 ? &grid.radii
                     : key == "polar"               ? &grid.polar
                     : key == "polar_forward_thick" ? &grid.polar_forward_thick
                     : key == "zenith"              ? &grid.zenith
                     : key == "azimuth"             ? &grid.azimuth
                     : key == "march_steps"         ? &grid.march_steps
                     : key == "orders"              ? &grid.orders
                                                    : nullptr;
        if (!field) throw py::value_error("grid." + key + ": unknown key");
        *field = item.second.cast<int>();
    }
    try {
        airlight::validate_sphere_grid(grid);
    } catch (const std::invalid_argument& e) {
        throw py::value_error(e.what());
    }
    return grid;
}

// The particle lighting table's shape (effects/particle_clouds/particle_table.hpp) from a dict.
airlight::ParticleTableShape parse_particle_table_shape(const py::dict& keys) {
    airlight::ParticleTableShape shape;
    for (auto item : keys) {
        const std::string key = py::str(item.first);
        if (key == "grid") {
            shape.grid = parse_sphere_grid(item.second.cast<py::dict>());
            continue;
        }
        if (key == "tau_min" || key == "tau_max") {
            (key == "tau_min" ? shape.tau_min : shape.tau_max) = item.second.cast<double>();
            continue;
        }
        if (key == "dense_terminator") {
            if (!py::isinstance<py::bool_>(item.second))
                throw py::type_error("shape.dense_terminator: must be true or false");
            shape.dense_terminator = item.second.cast<bool>();
            continue;
        }
        int* field = key == "entry"          ? &shape.entry
                     : key == "view_zenith"  ? &shape.view_zenith
                     : key == "view_azimuth" ? &shape.view_azimuth
                     : key == "taus"         ? &shape.taus
                     : key == "steps"        ? &shape.steps
                                             : nullptr;
        if (!field) throw py::value_error("shape." + key + ": unknown key");
        *field = item.second.cast<int>();
    }
    try {
        airlight::validate_particle_table_shape(shape);
    } catch (const std::invalid_argument& e) {
        throw py::value_error(e.what());
    }
    return shape;
}

PYBIND11_MODULE(_core, m) {
    m.doc() = "airlight native core (use the airlight package, not this module)";

    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const airlight::SceneError& e) {
            PyErr_SetString(e.kind() == airlight::SceneError::Kind::type ? PyExc_TypeError : PyExc_ValueError,
                            e.what());
        }
    });
    py::register_exception<airlight::BackendUnavailable>(m, "BackendUnavailableError", PyExc_RuntimeError);

    {
        namespace lim = airlight::scene_limits;
        py::dict limits;
        limits["max_film_size"] = lim::max_film_size;
        limits["max_film_pixels"] = lim::max_film_pixels;
        limits["max_scene_file_bytes"] = lim::max_scene_file_bytes;
        limits["min_light_radius"] = lim::min_light_radius;
        limits["max_light_radius"] = lim::max_light_radius;
        limits["default_light_radius"] = lim::default_light_radius;
        limits["min_cone_angle"] = lim::min_cone_angle;
        m.attr("scene_limits") = limits;  // include/airlight/scene_io.hpp, scene_limits
    }
    m.def(
        "validate_scene", [](py::handle scene) { return airlight::scene_to_json(scene_from_python(scene), -1); },
        "Validates a scene (dict or JSON text) and returns it as normalised JSON text.");
    m.def("load_scene_file",
          [](const std::string& path) { return airlight::scene_to_json(airlight::load_scene_file(path), -1); });
    m.def(
        "resize_film",
        [](int film_width, int film_height, int width, int height) {
            const airlight::Film f = airlight::resize_film(airlight::Film{film_width, film_height}, width, height);
            return std::make_pair(f.width, f.height);
        },
        "The film size for a width and/or height (0: not given), keeping the aspect ratio when one is given.",
        py::arg("film_width"), py::arg("film_height"), py::arg("width"), py::arg("height"));
    m.def("backend_info", []() {
        const airlight::AutoBackend a = airlight::choose_auto_backend();
        py::dict d;
        d["auto"] = airlight::backend_name(a.backend);
        d["gl_available"] = a.gl_available;
        d["gl_renderer"] = a.gl_available ? py::object(py::str(a.gl_renderer)) : py::object(py::none());
        d["gl_software"] = a.gl_software;
        d["gl_unavailable_reason"] =
            a.gl_available ? py::object(py::none()) : py::object(py::str(a.gl_unavailable_reason));
        return d;
    });
    m.def("is_software_gl_renderer", &airlight::is_software_gl_renderer, py::arg("gl_renderer"));
    m.def("gl_backend_available", []() {
        std::string reason;
        const bool ok = airlight::gl_backend_available(&reason);
        return py::make_tuple(ok, reason);
    });
    m.def("to_srgb8",
          [](const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance, float exposure) {
              const airlight::Image image = image_from_numpy(radiance);
              std::vector<std::uint8_t> bytes;
              try {
                  bytes = airlight::to_srgb8(image, exposure);
              } catch (const std::invalid_argument& e) {
                  throw py::value_error(e.what());
              }
              py::array_t<std::uint8_t> out({image.height, image.width, 3});
              std::memcpy(out.mutable_data(), bytes.data(), bytes.size());
              return out;
          });

    m.def(
        "display",
        [](const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance, std::optional<float> exposure,
           const std::string& tonemap, std::optional<float> white, bool glare, std::optional<double> pupil_diameter,
           bool eyelashes, double fov_y, airlight::Renderer* renderer, bool dither) {
            airlight::DisplaySettings settings = display_settings(exposure, tonemap, white);
            settings.dither = dither;
            settings.glare.enabled = glare;
            settings.glare.pupil_diameter_mm = pupil_diameter;
            settings.glare.eyelashes = eyelashes;
            const airlight::Image image = image_from_numpy(radiance);
            airlight::DisplayImage shown;
            try {
                py::gil_scoped_release release;
                shown = renderer != nullptr ? renderer->display(image, settings, fov_y)
                                            : airlight::display_image(image, settings, fov_y);
            } catch (const std::invalid_argument& e) {
                throw py::value_error(e.what());
            }
            py::array_t<std::uint8_t> out({image.height, image.width, 3});
            if (!shown.srgb8.empty()) std::memcpy(out.mutable_data(), shown.srgb8.data(), shown.srgb8.size());
            const airlight::DisplayReport& r = shown.report;
            py::dict report;
            report["exposure"] = r.exposure;
            report["white"] = r.white;
            report["dither"] = settings.dither;
            report["glare"] = r.glare;
            report["pupil_diameter"] = r.pupil_diameter_mm;
            report["glare_kernel_radius"] = r.glare_kernel_radius;
            report["glare_threshold"] = r.glare_threshold;
            report["glare_error_bound"] = r.glare_error_bound;
            report["glare_sources"] = r.glare_sources;
            report["glare_ms"] = r.glare_ms;
            report["tone_ms"] = r.tone_ms;
            return py::make_tuple(out, report);
        },
        py::arg("radiance"), py::arg("exposure"), py::arg("tonemap"), py::arg("white"), py::arg("glare"),
        py::arg("pupil_diameter"), py::arg("eyelashes"), py::arg("fov_y"), py::arg("renderer").none(true),
        py::arg("dither") = true);
    m.def(
        "auto_exposure",
        [](const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance) {
            const airlight::Image image = image_from_numpy(radiance);
            py::gil_scoped_release release;
            return airlight::auto_exposure(image);
        },
        py::arg("radiance"));
    m.def(
        "tone_curve",
        [](const py::array_t<float, py::array::c_style | py::array::forcecast>& luminance, const std::string& tonemap,
           std::optional<float> white) {
            const airlight::DisplaySettings settings = display_settings(std::nullopt, tonemap, white);
            const float w = settings.white ? *settings.white : airlight::default_white(settings.curve);
            py::array_t<float> out(std::vector<py::ssize_t>(luminance.shape(), luminance.shape() + luminance.ndim()));
            const float* src = luminance.data();
            float* dst = out.mutable_data();
            for (py::ssize_t i = 0; i < luminance.size(); ++i) {
                dst[i] = airlight::tone_map_luminance(settings.curve, src[i], w);
            }
            return out;
        },
        py::arg("luminance"), py::arg("tonemap"), py::arg("white"));
    m.def(
        "glare",
        [](const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance, double fov_y,
           double pupil_diameter, bool eyelashes) {
            const airlight::Image image = image_from_numpy(radiance);
            airlight::Image out;
            try {
                airlight::GlareOptions options;
                options.pupil_diameter_mm = pupil_diameter;
                options.eyelashes = eyelashes;
                py::gil_scoped_release release;
                const double pixel_angle = airlight::camera_pixel_angle(fov_y, std::max(image.height, 1));
                const airlight::GlareKernel kernel = airlight::glare_kernel_rgb(options, pixel_angle);
                out = airlight::glare_exact(image, kernel);
            } catch (const std::invalid_argument& e) {
                throw py::value_error(e.what());
            }
            py::array_t<float> result({out.height, out.width, 3});
            if (!out.rgb.empty()) std::memcpy(result.mutable_data(), out.rgb.data(), out.rgb.size() * sizeof(float));
            return result;
        },
        py::arg("radiance"), py::arg("fov_y"), py::arg("pupil_diameter"), py::arg("eyelashes"));
    m.def("default_white", [](const std::string& tonemap) {
        return airlight::default_white(display_settings(1.0f, tonemap, {}).curve);
    });

    m.def("tables_built", []() {
        py::dict out;
        std::map<std::string, int> builds;  // tables rebuilt for new parameters (the sky table) count each build
        for (const airlight::TableInfo& info : airlight::tables_built()) {
            py::dict d;
            d["builds"] = ++builds[info.name];
            d["width"] = info.width;
            d["height"] = info.height;
            d["bytes"] = info.bytes;
            d["build_seconds"] = info.build_seconds;
            // Tables of this name in memory now (a TableCache evicts the least recently used).
            const int resident = out.contains(info.name) ? out[info.name.c_str()]["resident"].cast<int>() : 0;
            d["resident"] = resident + (info.resident ? 1 : 0);
            out[info.name.c_str()] = d;
        }
        return out;
    });
    // The noise clouds' textures (effects/noise_clouds/noise.hpp), for the
    // float64 reference of tests and benchmarks: (shape, detail), each an
    // (n, n, n, 4) float32 array indexed [k, j, i, channel] (z, y, x).
    m.def(
        "cloud_noise_textures",
        [](int seed) {
            if (seed < 0 || seed > (1 << 30)) throw py::value_error("seed: must be in [0, 1073741824]");
            const airlight::CloudNoise noise = airlight::cloud_noise_textures(seed);
            auto as_array = [](const airlight::Table2D& t) {
                const py::ssize_t n = t.width;
                py::array_t<float> out({n, n, n, py::ssize_t(4)});
                std::memcpy(out.mutable_data(), t.texels.data(), t.texels.size() * sizeof(float));
                return out;
            };
            return py::make_tuple(as_array(*noise.shape), as_array(*noise.detail));
        },
        py::arg("seed"));
    // The particle clouds' reference particle (effects/particle_clouds/sphere_scattering.hpp): the
    // radiance of each scattering order along rays (origins and dirs (n, 3); the camera looks along dir)
    // for a unit sphere of optical radius tau lit by a sun of irradiance 1 from direction `sun`, solved
    // on `grid` (a dict of SphereGrid's fields); an (n, orders) float64 array, (n, orders + 1) with
    // grid["beyond"] (the last column: every order beyond summed).
    m.def(
        "particle_sphere_radiance",
        [](double tau, double g, std::array<double, 3> sun,
           py::array_t<double, py::array::c_style | py::array::forcecast> origins,
           py::array_t<double, py::array::c_style | py::array::forcecast> dirs, py::dict grid_keys, int steps) {
            const airlight::SphereGrid grid = parse_sphere_grid(grid_keys);
            if (steps < 1 || steps > 1 << 16) throw py::value_error("steps: must be in [1, 65536]");
            if (origins.ndim() != 2 || origins.shape(1) != 3 || dirs.ndim() != 2 || dirs.shape(1) != 3 ||
                dirs.shape(0) != origins.shape(0))
                throw py::value_error("origins, dirs: must both be (n, 3) arrays");
            const double norm = std::sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
            if (!(norm > 0.0) || !std::isfinite(norm)) throw py::value_error("sun: must be a nonzero finite vector");
            // The solver's frame: e1, e2, sun (its +z).
            const std::array<double, 3> s{sun[0] / norm, sun[1] / norm, sun[2] / norm};
            std::array<double, 3> e1 =
                std::fabs(s[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
            const double proj = e1[0] * s[0] + e1[1] * s[1] + e1[2] * s[2];
            for (int i = 0; i < 3; ++i) e1[i] -= proj * s[i];
            const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
            for (double& x : e1) x /= n1;
            const std::array<double, 3> e2{s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                                           s[0] * e1[1] - s[1] * e1[0]};
            auto to_frame = [&](const double* x, double* out) {
                out[0] = x[0] * e1[0] + x[1] * e1[1] + x[2] * e1[2];
                out[1] = x[0] * e2[0] + x[1] * e2[1] + x[2] * e2[2];
                out[2] = x[0] * s[0] + x[1] * s[1] + x[2] * s[2];
            };
            std::unique_ptr<airlight::SphereScattering> solved;
            {
                py::gil_scoped_release release;
                try {
                    solved = std::make_unique<airlight::SphereScattering>(tau, g, grid);
                } catch (const std::invalid_argument& e) {
                    py::gil_scoped_acquire acquire;
                    throw py::value_error(e.what());
                }
            }
            const py::ssize_t n = origins.shape(0);
            const py::ssize_t columns = grid.orders + (grid.beyond ? 1 : 0);
            py::array_t<double> out({n, columns});
            const double* o = origins.data();
            const double* d = dirs.data();
            double* r = out.mutable_data();
            // The rays in the solver's frame, checked first; then marched on every core.
            std::vector<double> frame_rays(size_t(n) * 6);
            for (py::ssize_t i = 0; i < n; ++i) {
                double* oo = &frame_rays[size_t(i) * 6];
                double* dd = oo + 3;
                to_frame(o + 3 * i, oo);
                to_frame(d + 3 * i, dd);
                const double len = std::sqrt(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
                if (!(len > 0.0) || !std::isfinite(len))
                    throw py::value_error("dirs: every row must be a nonzero finite vector");
                for (int k = 0; k < 3; ++k) dd[k] /= len;
            }
            {
                py::gil_scoped_release release;
                airlight::numerics::parallel_for(int(n), [&](int i) {
                    const double* ray = &frame_rays[size_t(i) * 6];
                    const std::vector<double> orders = solved->radiance_orders(ray, ray + 3, steps);
                    std::copy(orders.begin(), orders.end(), r + size_t(i) * columns);
                });
            }
            return out;
        },
        py::arg("tau"), py::arg("g"), py::arg("sun"), py::arg("origins"), py::arg("dirs"), py::arg("grid") = py::dict(),
        py::arg("steps") = 256);
    // The particle clouds' lighting table (effects/particle_clouds/particle_table.hpp), for tests and
    // the resolution analysis: built for g and a shape dict; lookup(tau, normals, views, sun) gives an
    // (n, 2) array (order 1, orders 2..N) for rays entering where the unit outward normal is `normals`.
    py::class_<airlight::ParticleTable>(m, "ParticleTable")
        .def(py::init([](double g, py::dict shape) {
                 const airlight::ParticleTableShape parsed = parse_particle_table_shape(shape);
                 py::gil_scoped_release release;
                 try {
                     return std::make_unique<airlight::ParticleTable>(g, parsed);
                 } catch (const std::invalid_argument& e) {
                     py::gil_scoped_acquire acquire;
                     throw py::value_error(e.what());
                 }
             }),
             py::arg("g"), py::arg("shape") = py::dict())
        .def_static(
            "for_quality",
            [](double g, const std::string& quality) {
                if (quality != "full" && quality != "preview")
                    throw py::value_error("quality: must be \"full\" or \"preview\"");
                const airlight::ParticleTableShape shape = airlight::particle_table_shape(
                    quality == "full" ? airlight::ParticleTableQuality::full : airlight::ParticleTableQuality::preview);
                py::gil_scoped_release release;
                try {
                    return std::make_unique<airlight::ParticleTable>(g, shape);
                } catch (const std::invalid_argument& e) {
                    py::gil_scoped_acquire acquire;
                    throw py::value_error(e.what());
                }
            },
            "The table the renderer builds for quality.particle_table (\"full\" or \"preview\").", py::arg("g"),
            py::arg("quality"))
        .def_property_readonly("build_seconds", &airlight::ParticleTable::build_seconds)
        .def_property_readonly("bytes",
                               [](const airlight::ParticleTable& t) { return t.nodes().size() * sizeof(float); })
        .def(
            "lookup",
            [](const airlight::ParticleTable& t, py::array_t<double, py::array::c_style | py::array::forcecast> taus,
               py::array_t<double, py::array::c_style | py::array::forcecast> normals,
               py::array_t<double, py::array::c_style | py::array::forcecast> views, std::array<double, 3> sun) {
                const py::ssize_t n = normals.ndim() == 2 ? normals.shape(0) : -1;
                if (n < 0 || normals.shape(1) != 3 || views.ndim() != 2 || views.shape(0) != n || views.shape(1) != 3 ||
                    taus.ndim() != 1 || taus.shape(0) != n)
                    throw py::value_error("taus, normals, views: must be (n,), (n, 3), (n, 3) arrays");
                py::array_t<double> out({n, py::ssize_t(2)});
                double* r = out.mutable_data();
                for (py::ssize_t i = 0; i < n; ++i) {
                    const std::array<double, 2> v =
                        t.lookup(taus.data()[i], normals.data() + 3 * i, views.data() + 3 * i, sun.data());
                    r[2 * i] = v[0];
                    r[2 * i + 1] = v[1];
                }
                return out;
            },
            py::arg("taus"), py::arg("normals"), py::arg("views"), py::arg("sun"));
    // The particle clouds' particles of a scene's frame, as the shading pass reads them (nearest
    // first; effects/particle_clouds/particle_field.hpp), with the modelling's counts and times: for
    // the float64 compositing reference and the benchmark.
    m.def(
        "particle_frame",
        [](py::handle scene_obj) {
            const Scene scene = scene_from_python(scene_obj);
            airlight::ParticleField field;
            airlight::ScreenTiles tiles;
            std::vector<airlight::Particle> casters;
            double bin_seconds = 0.0;
            {
                py::gil_scoped_release release;
                const airlight::FrameData data = airlight::make_frame_data(scene);
                const airlight::ParticleCamera cam = airlight::particle_camera(data);
                const glm::vec3 sun(data.frame.sky.sun_direction);
                field = airlight::particle_field(scene.particle_clouds, cam, sun);
                casters = airlight::model_particles(scene.particle_clouds, cam.position, sun);
                const auto start = std::chrono::steady_clock::now();
                tiles = airlight::bin_particles(field.particles, cam, airlight::shader::PARTICLE_TILE_SIZE);
                bin_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
            const py::ssize_t n = py::ssize_t(field.particles.size());
            py::array_t<double> center({n, py::ssize_t(3)});
            py::array_t<double> radius(n), tau(n), sun(n), sky(n);
            for (py::ssize_t i = 0; i < n; ++i) {
                const airlight::Particle& p = field.particles[size_t(i)];
                for (int k = 0; k < 3; ++k) center.mutable_data()[3 * i + k] = p.center[k];
                radius.mutable_data()[i] = p.radius;
                tau.mutable_data()[i] = p.tau;
                sun.mutable_data()[i] = p.sun_transmittance;
                sky.mutable_data()[i] = p.sky_visibility;
            }
            py::dict out;
            out["center"] = center;
            out["radius"] = radius;
            out["tau"] = tau;
            out["sun_transmittance"] = sun;
            out["sky_visibility"] = sky;
            const airlight::ParticleFieldStats& s = field.stats;
            out["columns"] = s.columns;
            out["particles"] = s.particles;
            out["drawn"] = s.drawn;
            out["tile_entries"] = tiles.entries.size();
            out["model_seconds"] = s.model_seconds;
            out["shadow_seconds"] = s.shadow_seconds;
            out["sort_seconds"] = s.sort_seconds;
            out["bin_seconds"] = bin_seconds;
            // Every particle, the culled ones too (the shadow casters: model_particles).
            py::array_t<double> all_center({py::ssize_t(casters.size()), py::ssize_t(3)});
            py::array_t<double> all_radius(py::ssize_t(casters.size())), all_tau(py::ssize_t(casters.size()));
            for (size_t i = 0; i < casters.size(); ++i) {
                for (int k = 0; k < 3; ++k) all_center.mutable_data()[3 * i + k] = casters[i].center[k];
                all_radius.mutable_data()[i] = casters[i].radius;
                all_tau.mutable_data()[i] = casters[i].tau;
            }
            py::dict all;
            all["center"] = all_center;
            all["radius"] = all_radius;
            all["tau"] = all_tau;
            out["casters"] = all;
            return out;
        },
        py::arg("scene"));
    // The falling rain's drops (effects/falling_rain/drops.hpp): every drop within its draw
    // distance of the camera at the middle of the exposure, in any direction (the frame keeps
    // those whose streaks reach the film), for the tests of the rain field and the benchmark.
    m.def(
        "rain_drops",
        [](py::handle scene_obj) {
            const Scene scene = scene_from_python(scene_obj);
            std::vector<airlight::RainDrop> drops;
            {
                py::gil_scoped_release release;
                drops = airlight::rain_drops(scene.falling_rain, glm::dvec3(scene.camera.position),
                                             scene.camera.exposure_time);
            }
            const py::ssize_t n = py::ssize_t(drops.size());
            py::array_t<double> position({n, py::ssize_t(3)}), velocity({n, py::ssize_t(3)});
            py::array_t<double> diameter(n), weight(n);
            py::array_t<std::uint64_t> id(n);
            for (py::ssize_t i = 0; i < n; ++i) {
                const airlight::RainDrop& d = drops[size_t(i)];
                for (int k = 0; k < 3; ++k) {
                    position.mutable_data()[3 * i + k] = d.position[k];
                    velocity.mutable_data()[3 * i + k] = d.velocity[k];
                }
                diameter.mutable_data()[i] = d.diameter;
                weight.mutable_data()[i] = d.weight;
                id.mutable_data()[i] = d.id;
            }
            py::dict out;
            out["position"] = position;
            out["velocity"] = velocity;
            out["diameter"] = diameter;
            out["weight"] = weight;
            out["id"] = id;
            return out;
        },
        py::arg("scene"));
    m.def("rain_terminal_speed", &airlight::terminal_speed, py::arg("diameter_mm"));
    m.def(
        "rain_draw_distance",
        [](py::handle scene_obj, double d) {
            return airlight::rain_draw_distance(scene_from_python(scene_obj).falling_rain, d);
        },
        py::arg("scene"), py::arg("diameter_mm"));
    m.def(
        "drop_phase_order",
        [](double n, int p, int bins, int samples) {
            if (!(n > 1.0 && n < 2.0)) throw py::value_error("n: must be in (1, 2)");
            if (p < 0 || p > 32) throw py::value_error("p: must be in [0, 32]");
            if (bins < 1 || bins > 100000) throw py::value_error("bins: must be in [1, 100000]");
            if (samples < 1 || samples > (1 << 26)) throw py::value_error("samples: must be in [1, 2^26]");
            const std::vector<double> f = airlight::drop_phase_order(n, p, bins, samples);
            py::array_t<double> out(py::ssize_t(f.size()));
            std::memcpy(out.mutable_data(), f.data(), f.size() * sizeof(double));
            return out;
        },
        py::arg("n"), py::arg("p"), py::arg("bins"), py::arg("samples"));
    m.def("drop_order_energy", &airlight::drop_order_energy, py::arg("n"), py::arg("p"), py::arg("incidence"));
    m.attr("DROP_ORDERS") = airlight::DROP_ORDERS;
    m.attr("MS_RAIN_LADDER_FLOOR") = airlight::MS_RAIN_LADDER_FLOOR;  // effects/multiple_scattering/ms_tables.hpp
    // Rainbow tables (effects/rainbow/rainbow.hpp): exposed for tests and benchmarks.
    m.def(
        "rainbow_phase_table",
        [](double rate, int wavelengths) {
            if (!(rate > 0.0) || !std::isfinite(rate)) throw py::value_error("rate: must be a positive number (mm/h)");
            if (!airlight::is_rainbow_wavelength_count(wavelengths))
                throw py::value_error(std::string("wavelengths: must be ") + airlight::RAINBOW_WAVELENGTH_COUNTS);
            const airlight::Table2D& t = airlight::rainbow_phase_table(rate, wavelengths);
            py::array_t<float> out({t.width, 4});
            std::memcpy(out.mutable_data(), t.texels.data(), t.texels.size() * sizeof(float));
            return out;
        },
        py::arg("rate"), py::arg("wavelengths"));
    m.def(
        "rainbow_spectral_table",
        [](int samples, unsigned long long seed, const std::vector<int>& wavelengths) {
            // samples 0: the embedded table; else a new one (Monte Carlo, as
            // build/cpp/make_rainbow_table computes it) for the given nodes.
            airlight::RainbowSpectralTable computed;
            if (samples != 0) {
                if (samples < 64 || samples > 1 << 20) throw py::value_error("samples: must be in [64, 1048576]");
                for (int w : wavelengths)
                    if (w < 0 || w >= airlight::RAINBOW_WAVELENGTHS)
                        throw py::value_error("wavelengths: node indices are 0.." +
                                              std::to_string(airlight::RAINBOW_WAVELENGTHS - 1));
                airlight::RainbowSampling s;
                s.samples_per_wavelength = samples;
                s.seed = seed;
                s.wavelengths = wavelengths;
                py::gil_scoped_release release;
                computed = airlight::compute_rainbow_spectral_table(s);
            }
            const airlight::RainbowSpectralTable& t = samples != 0 ? computed : airlight::rainbow_spectral_table();
            const py::ssize_t nr = py::ssize_t(t.rates.size()), nw = py::ssize_t(t.wavelengths_nm.size()),
                              na = py::ssize_t(t.angles_deg.size());
            py::array_t<float> phase({nr, nw, na}), rel_error({nr, nw, na});
            std::memcpy(phase.mutable_data(), t.phase.data(), t.phase.size() * sizeof(float));
            std::memcpy(rel_error.mutable_data(), t.rel_error.data(), t.rel_error.size() * sizeof(float));
            py::dict d;
            d["wavelengths_nm"] = py::array_t<double>(py::ssize_t(nw), t.wavelengths_nm.data());
            d["rates"] = py::array_t<double>(py::ssize_t(nr), t.rates.data());
            d["angles_deg"] = py::array_t<double>(py::ssize_t(na), t.angles_deg.data());
            d["phase"] = phase;
            d["rel_error"] = rel_error;
            d["samples_per_wavelength"] = t.samples_per_wavelength;
            return d;
        },
        py::arg("samples") = 0, py::arg("seed") = 1, py::arg("wavelengths") = std::vector<int>{});
    // The point lamps' multiple-scattering table (effects/multiple_scattering/point_source.hpp), the
    // cached one a frame with this HG g and per-channel albedo uses: log L rows, then log E rows
    // (lamp_ms_math.glsl). For tests.
    m.def(
        "lamp_ms_table",
        [](double g, const std::array<double, 3>& albedo) {
            if (!(g > -1.0 && g < 1.0)) throw py::value_error("g: must be in (-1, 1)");
            for (double a : albedo)
                if (!(a >= 0.0 && a <= 1.0)) throw py::value_error("albedo: each must be in [0, 1]");
            airlight::Phase phase;
            phase.type = airlight::PhaseType::hg;
            phase.g = float(g);
            std::shared_ptr<const airlight::Table2D> t;
            {
                py::gil_scoped_release release;
                t = airlight::lamp_ms_table(airlight::point_source_phase(phase), albedo);
            }
            py::array_t<float> out({t->height, t->width, 4});
            std::memcpy(out.mutable_data(), t->texels.data(), t->texels.size() * sizeof(float));
            return out;
        },
        py::arg("g"), py::arg("albedo"));
    m.def("rainbow_rgb_weights", [](int count) {
        if (!airlight::is_rainbow_wavelength_count(count))
            throw py::value_error(std::string("count: must be ") + airlight::RAINBOW_WAVELENGTH_COUNTS);
        const std::vector<float> w = airlight::rainbow_rgb_weights(count);
        py::array_t<float> out({py::ssize_t(count), py::ssize_t(3)});
        std::memcpy(out.mutable_data(), w.data(), w.size() * sizeof(float));
        return out;
    });
    m.def("water_refractive_index", &airlight::water_refractive_index, py::arg("wavelength_nm"));
    m.def(
        "mie_sun_disc_phase",
        [](double refractive_index, double diameter_mm, double wavelength_nm, const std::vector<double>& angles_deg,
           int n_radial) {
            if (!(diameter_mm > 0.0 && diameter_mm <= 10.0)) throw py::value_error("diameter_mm: must be in (0, 10]");
            if (!(wavelength_nm >= 200.0 && wavelength_nm <= 2000.0))
                throw py::value_error("wavelength_nm: must be in [200, 2000]");
            if (n_radial < 1 || n_radial > 64) throw py::value_error("n_radial: must be in [1, 64]");
            const std::vector<double> p =
                airlight::mie_sun_disc_phase(refractive_index, diameter_mm, wavelength_nm, angles_deg, n_radial);
            return py::array_t<double>(py::ssize_t(p.size()), p.data());
        },
        py::arg("refractive_index"), py::arg("diameter_mm"), py::arg("wavelength_nm"), py::arg("angles_deg"),
        py::arg("n_radial") = 12);
    m.def(
        "mie_size_average_phase",
        // rate > 0: Marshall-Palmer drops of 0.1-3.5 mm; rate 0: N(D) ~
        // exp(-slope D) on [d_min, d_max] (mm).
        [](double rate, double wavelength_nm, const std::vector<double>& angles_deg, int n_sizes, double slope,
           double d_min, double d_max) {
            airlight::DropSizes sizes{slope, d_min, d_max};
            if (rate != 0.0) {
                if (!(rate > 0.0) || !std::isfinite(rate))
                    throw py::value_error("rate: must be a positive number (mm/h), or 0 with slope, d_min, d_max");
                sizes = airlight::DropSizes{airlight::marshall_palmer_slope(rate)};
            }
            if (!(sizes.slope_per_mm >= 0.0 && sizes.slope_per_mm < 1e6))
                throw py::value_error("slope: must be in [0, 1e6)");
            if (!(sizes.d_min_mm >= 1e-4 && sizes.d_min_mm < sizes.d_max_mm && sizes.d_max_mm <= 10.0))
                throw py::value_error("d_min, d_max: need 1e-4 <= d_min < d_max <= 10 (mm)");
            if (!(wavelength_nm >= 200.0 && wavelength_nm <= 2000.0))
                throw py::value_error("wavelength_nm: must be in [200, 2000]");
            if (n_sizes < 1 || n_sizes > 100000) throw py::value_error("n_sizes: must be in [1, 100000]");
            std::vector<double> p;
            {
                py::gil_scoped_release release;
                p = airlight::mie_size_average_phase(sizes, wavelength_nm, angles_deg, n_sizes);
            }
            return py::array_t<double>(py::ssize_t(p.size()), p.data());
        },
        py::arg("rate"), py::arg("wavelength_nm"), py::arg("angles_deg"), py::arg("n_sizes"), py::arg("slope") = 0.0,
        py::arg("d_min") = airlight::RAINDROP_D_MIN_MM, py::arg("d_max") = airlight::RAINDROP_D_MAX_MM);
    m.def(
        "solve_plane_parallel",
        // The slab from the ground up: layer_tops (m), depths [layer][species][channel];
        // phases per species: "rayleigh", ("hg", g) or ("legendre", [chi_0, chi_1, ...]);
        // sky(mu, phi) -> (r, g, b) for look directions mu > 0, phi from the sun's azimuth.
        [](const std::vector<py::object>& phases, const std::vector<double>& layer_tops,
           const std::vector<std::vector<std::array<double, 3>>>& extinction_depth,
           const std::vector<std::vector<std::array<double, 3>>>& scattering_depth, double sun_mu,
           const std::array<double, 3>& sun_irradiance, py::object sky, const std::array<double, 3>& ground_albedo,
           int streams, int max_fourier_mode, double initial_depth, bool delta_m, const std::vector<double>& view_mu,
           const std::vector<double>& view_phi, double azimuth_tolerance) {
            airlight::SlabAtmosphere atm;
            for (const py::object& p : phases) {
                if (py::isinstance<py::str>(p) && p.cast<std::string>() == "rayleigh") {
                    atm.phases.push_back(airlight::PhaseFunction::rayleigh());
                    continue;
                }
                const auto t = p.cast<py::tuple>();
                const std::string kind = t[0].cast<std::string>();
                if (kind == "hg") {
                    const double g = t[1].cast<double>();
                    if (!(g > -1.0 && g < 1.0)) throw py::value_error("phases: HG g must be in (-1, 1)");
                    atm.phases.push_back(airlight::PhaseFunction::henyey_greenstein(g));
                } else if (kind == "legendre") {
                    atm.phases.push_back(airlight::PhaseFunction::legendre(t[1].cast<std::vector<double>>()));
                } else {
                    throw py::value_error("phases: each must be 'rayleigh', ('hg', g) or ('legendre', moments)");
                }
            }
            if (extinction_depth.size() != layer_tops.size() || scattering_depth.size() != layer_tops.size())
                throw py::value_error("extinction_depth, scattering_depth: one entry per layer");
            double bottom = 0.0;
            for (size_t k = 0; k < layer_tops.size(); ++k) {
                if (!(layer_tops[k] > bottom)) throw py::value_error("layer_tops: must increase from above 0");
                if (extinction_depth[k].size() != atm.phases.size() || scattering_depth[k].size() != atm.phases.size())
                    throw py::value_error("extinction_depth, scattering_depth: one entry per species");
                for (size_t i = 0; i < atm.phases.size(); ++i)
                    for (int c = 0; c < 3; ++c) {
                        const double t = extinction_depth[k][i][size_t(c)], sc = scattering_depth[k][i][size_t(c)];
                        if (!(t >= 0.0 && t < 1e7 && sc >= 0.0 && sc <= t))
                            throw py::value_error("depths: need 0 <= scattering <= extinction < 1e7");
                    }
                airlight::SlabLayer l;
                l.bottom = bottom;
                l.top = layer_tops[k];
                l.extinction_depth = extinction_depth[k];
                l.scattering_depth = scattering_depth[k];
                atm.layers.push_back(l);
                bottom = layer_tops[k];
            }
            airlight::SlabIllumination light;
            if (!(sun_mu >= -1.0 && sun_mu <= 1.0)) throw py::value_error("sun_mu: must be in [-1, 1]");
            light.sun_mu = sun_mu;
            light.sun_irradiance = sun_irradiance;
            light.ground_albedo = ground_albedo;
            if (!sky.is_none())
                light.sky_radiance = [sky](double mu, double phi) {
                    return sky(mu, phi).cast<std::array<double, 3>>();
                };
            const airlight::SolverOptions o =
                solver_options(streams, max_fourier_mode, initial_depth, delta_m, view_mu, view_phi, azimuth_tolerance);
            return field_to_python(airlight::solve_plane_parallel(atm, light, o));
        },
        py::arg("phases"), py::arg("layer_tops"), py::arg("extinction_depth"), py::arg("scattering_depth"),
        py::arg("sun_mu") = 0.0, py::arg("sun_irradiance") = std::array<double, 3>{0.0, 0.0, 0.0},
        py::arg("sky") = py::none(), py::arg("ground_albedo") = std::array<double, 3>{0.0, 0.0, 0.0},
        py::arg("streams") = 16, py::arg("max_fourier_mode") = -1, py::arg("initial_depth") = 1.0 / 16.0,
        py::arg("delta_m") = true, py::arg("view_mu") = std::vector<double>{},
        py::arg("view_phi") = std::vector<double>{}, py::arg("azimuth_tolerance") = 1e-4);
    m.def(
        "solve_plane_parallel_scene",
        // A scene's atmosphere, sky and sun (slab_from_species, slab_illumination)
        // over the levels slab_levels(segments, max_layer_depth).
        [](py::handle scene_obj, double ground_albedo, int segments, double max_layer_depth, int streams,
           double initial_depth, double azimuth_tolerance) {
            const Scene scene = scene_from_python(scene_obj);
            if (!(ground_albedo >= 0.0 && ground_albedo <= 1.0))
                throw py::value_error("ground_albedo: must be in [0, 1]");
            if (segments < 2 || segments > 64) throw py::value_error("segments: must be in [2, 64]");
            if (!(max_layer_depth > 0.0)) throw py::value_error("max_layer_depth: must be positive");
            airlight::shader::SpeciesGpu species[airlight::shader::SPECIES_COUNT];
            airlight::make_species_gpu(scene.atmosphere, species);
            const std::vector<double> levels = airlight::slab_levels(species, segments, max_layer_depth);
            const airlight::SlabAtmosphere atm = airlight::slab_from_species(species, levels);
            const airlight::SlabIllumination light = airlight::slab_illumination(
                airlight::make_sky_gpu(scene.sky, scene.sun), {ground_albedo, ground_albedo, ground_albedo});
            const airlight::SolverOptions o =
                solver_options(streams, -1, initial_depth, true, {}, {}, azimuth_tolerance);
            airlight::MultipleScatteringField f;
            {
                py::gil_scoped_release release;
                f = airlight::solve_plane_parallel(atm, light, o);
            }
            py::dict d = field_to_python(f);
            d["layers"] = py::ssize_t(atm.layers.size());
            return d;
        },
        py::arg("scene"), py::arg("ground_albedo") = 0.0, py::arg("segments") = 16, py::arg("max_layer_depth") = 2.0,
        py::arg("streams") = 16, py::arg("initial_depth") = 1.0 / 16.0, py::arg("azimuth_tolerance") = 1e-4);
    m.def("write_pfm",
          [](const std::string& path, const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance) {
              airlight::write_pfm(path, image_from_numpy(radiance));
          });

    m.def(
        "write_exr",
        [](const std::string& path, const std::vector<std::pair<std::string, FloatArray>>& images, bool half) {
            int width = 0, height = 0;
            const std::vector<airlight::NamedImage> named = named_images_from_numpy(images, width, height);
            try {
                py::gil_scoped_release release;
                airlight::write_exr(path, width, height, named, half);
            } catch (const std::runtime_error& e) {
                throw_os_error(e);
            }
        },
        py::arg("path"), py::arg("images"), py::arg("half") = false);
    m.def(
        "read_exr",
        [](const std::string& path) {
            int width = 0, height = 0;
            std::vector<airlight::NamedImage> images;
            try {
                py::gil_scoped_release release;
                images = airlight::read_exr(path, width, height);
            } catch (const std::runtime_error& e) {
                throw_os_error(e);
            }
            py::list out;
            for (const airlight::NamedImage& im : images) {
                std::vector<py::ssize_t> shape = {height, width};
                if (im.components != 1) shape.push_back(im.components);
                // A channel name is any bytes in a foreign file: undecodable ones replaced.
                auto name = py::reinterpret_steal<py::str>(
                    PyUnicode_DecodeUTF8(im.name.data(), py::ssize_t(im.name.size()), "replace"));
                if (!name) throw py::error_already_set();
                out.append(py::make_tuple(name, py::array_t<float>(shape, im.values.data())));
            }
            return out;
        },
        py::arg("path"));

    py::class_<airlight::Renderer>(m, "Renderer")
        .def(py::init([](const std::string& backend) {
                 if (backend == "gl") return std::make_unique<airlight::Renderer>(airlight::Backend::gl);
                 if (backend == "cpu") return std::make_unique<airlight::Renderer>(airlight::Backend::cpu);
                 throw py::value_error("backend: must be 'gl' or 'cpu', got '" + backend + "'");
             }),
             py::arg("backend"))
        .def_property_readonly("backend",
                               [](const airlight::Renderer& r) { return airlight::backend_name(r.backend()); })
        .def("set_cpu_threads", &airlight::Renderer::set_cpu_threads)
        .def_property_readonly("cpu_fallback_pixels", &airlight::Renderer::cpu_fallback_pixels)
        .def("render",
             [](airlight::Renderer& r, py::handle scene_obj) {
                 const Scene scene = scene_from_python(scene_obj);
                 return image_to_numpy(render_interruptibly(r, scene));
             })
        // The named render outputs (airlight.render_outputs: names checked by the
        // caller), each a float32 array (height, width[, 3]), computed in one pass.
        // With `backplate` (float32 (height, width, 4): linear RGB and depth, the
        // film's size; airlight.photo), it ends each camera ray (effects/photo).
        .def(
            "render_outputs",
            [](airlight::Renderer& r, py::handle scene_obj, const std::vector<std::string>& names,
               std::optional<py::array_t<float, py::array::c_style | py::array::forcecast>> backplate,
               bool depth_along_axis, std::optional<std::array<float, 4>> intrinsics) {
                Scene scene = scene_from_python(scene_obj);
                if (backplate) {
                    const py::array_t<float, py::array::c_style | py::array::forcecast>& b = *backplate;
                    if (b.ndim() != 3 || b.shape(0) != scene.film.height || b.shape(1) != scene.film.width ||
                        b.shape(2) != 4)
                        throw py::value_error("backplate: expected shape (" + std::to_string(scene.film.height) + ", " +
                                              std::to_string(scene.film.width) + ", 4)");
                    scene.backplate.rgbd = std::make_shared<const std::vector<float>>(b.data(), b.data() + b.size());
                    scene.backplate.width = scene.film.width;
                    scene.backplate.height = scene.film.height;
                    scene.backplate.depth_along_axis = depth_along_axis;
                    if (intrinsics)
                        for (int k = 0; k < 4; ++k) scene.backplate.intrinsics[k] = (*intrinsics)[size_t(k)];
                }
                bool extra = false;
                for (const std::string& name : names) extra = extra || name != "radiance";
                const airlight::Image image = render_interruptibly(r, scene, extra);
                py::dict result;
                for (const std::string& name : names) {
                    int components = 3;
                    for (const airlight::RenderOutput& o : airlight::render_outputs())
                        if (o.name == name) components = o.components;
                    std::vector<float> values;
                    try {
                        values = airlight::output_values(image, name);
                    } catch (const std::invalid_argument& e) {
                        throw py::value_error(std::string("outputs: ") + e.what());
                    }
                    py::array_t<float> a(components == 1 ? std::vector<py::ssize_t>{image.height, image.width}
                                                         : std::vector<py::ssize_t>{image.height, image.width, 3});
                    std::copy(values.begin(), values.end(), a.mutable_data());
                    result[py::str(name)] = a;
                }
                return result;
            },
            py::arg("scene"), py::arg("names"), py::arg("backplate") = py::none(), py::arg("depth_along_axis") = false,
            py::arg("intrinsics") = py::none());
    m.def("render_outputs", [] {
        py::list list;
        for (const airlight::RenderOutput& o : airlight::render_outputs()) {
            py::dict d;
            d["name"] = o.name;
            d["components"] = o.components;
            d["description"] = o.description;
            d["layer"] = o.layer;
            list.append(d);
        }
        return list;
    });
}
