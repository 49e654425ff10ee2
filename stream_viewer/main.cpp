// geomip-view: progressive file/HTTP streaming viewer of .gip packs (issue 6; Praun, Sweldens, Schröder 2001
// §6). Exit codes: 0 ok (whole pack shown); 2 bad usage, or nothing could be shown (missing file, HTTP error,
// not a pack); 3 the stream failed part-way (the last complete level was shown and written); 1 internal
// failure (OpenGL).
#include <CLI/CLI.hpp>
#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "codec/status.h"
#include "stream_viewer/pack_source.h"
#include "stream_viewer/png_write.h"
#include "stream_viewer/renderer.h"

namespace {

using namespace geomip::viewer;
namespace morph = geomip::morph;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0, kExitFailure = 1, kExitBadInput = 2, kExitPartial = 3;

struct Options {
  std::string source;
  int level = -1;
  std::optional<float> morph;
  std::string schedule = "linear";
  int bands = 5;
  int model = 0;
  bool animate = false;
  bool no_align = false;
  int frames = 0;
  int width = 1280, height = 720;
  std::string screenshot, first_screenshot;
  bool bench = false, checker = false, wireframe = false;
  bool decode_each_prefix = false;
  std::uint64_t limit_rate = 0;
  std::uint64_t stall_timeout = 20;
  double timeout = 120;
  float yaw = 0.6f, pitch = 0.35f, distance = 3.2f;
  bool distance_given = false;  // --distance: no automatic framing
  std::string up;               // the models' up axis in their units; empty: the pack's frame
};

struct Ui {
  RenderSettings settings;
  bool auto_level = false;
  bool animate = false;
  float anim = 0;  // position in [0, models) when animating
  bool dragging = false;
  bool camera_moved = false;  // the user dragged or zoomed: the camera is no longer framed automatically
  double last_x = 0, last_y = 0;
  int max_level = 0;
};

int auto_level(const RenderSettings& s, int max_level, int patches) {
  // Screen-space error: aim for grid quads of about 4 pixels.
  const float px = static_cast<float>(s.height) /
                   (2.0f * s.camera.distance * std::tan(s.camera.fov_y_deg * 3.14159265f / 360.0f));
  const float per_patch = px / std::sqrt(static_cast<float>(std::max(patches, 1)));
  const int k = static_cast<int>(std::ceil(std::log2(std::max(per_patch / 4.0f, 1.0f))));
  return std::clamp(k, 0, max_level);
}

void key_callback(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  auto* ui = static_cast<Ui*>(glfwGetWindowUserPointer(w));
  auto& s = ui->settings;
  switch (key) {
    case GLFW_KEY_ESCAPE: case GLFW_KEY_Q: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_UP: case GLFW_KEY_EQUAL:
      ui->auto_level = false;
      s.level = std::min((s.level < 0 ? ui->max_level : s.level) + 1, ui->max_level);
      break;
    case GLFW_KEY_DOWN: case GLFW_KEY_MINUS:
      ui->auto_level = false;
      s.level = std::max((s.level < 0 ? ui->max_level : s.level) - 1, 0);
      break;
    case GLFW_KEY_L: ui->auto_level = !ui->auto_level; break;
    case GLFW_KEY_C: s.checker = !s.checker; break;
    case GLFW_KEY_W: s.wireframe = !s.wireframe; break;
    case GLFW_KEY_RIGHT: s.t = std::min(s.t + 0.05f, 1.0f); ui->animate = false; break;
    case GLFW_KEY_LEFT: s.t = std::max(s.t - 0.05f, 0.0f); ui->animate = false; break;
    case GLFW_KEY_SPACE: ui->animate = !ui->animate; break;
    case GLFW_KEY_S:
      s.schedule = s.schedule == morph::MorphSchedule::kLinear ? morph::MorphSchedule::kWavelet : morph::MorphSchedule::kLinear;
      break;
    default: break;
  }
}

void mouse_button(GLFWwindow* w, int button, int action, int) {
  auto* ui = static_cast<Ui*>(glfwGetWindowUserPointer(w));
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    ui->dragging = action == GLFW_PRESS;
    glfwGetCursorPos(w, &ui->last_x, &ui->last_y);
  }
}

void cursor_pos(GLFWwindow* w, double x, double y) {
  auto* ui = static_cast<Ui*>(glfwGetWindowUserPointer(w));
  if (!ui->dragging) return;
  ui->camera_moved = true;
  ui->settings.camera.yaw -= static_cast<float>(x - ui->last_x) * 0.01f;
  ui->settings.camera.pitch = std::clamp(ui->settings.camera.pitch + static_cast<float>(y - ui->last_y) * 0.01f,
                                         -1.5f, 1.5f);
  ui->last_x = x;
  ui->last_y = y;
}

void scroll(GLFWwindow* w, double, double dy) {
  auto* ui = static_cast<Ui*>(glfwGetWindowUserPointer(w));
  ui->camera_moved = true;
  ui->settings.camera.distance = std::clamp(ui->settings.camera.distance * std::pow(0.9f, static_cast<float>(dy)),
                                            0.3f, 20.0f);
}

/// The xyz samples of the scene models themselves: per patch the sum of its bands (one band: the geometry; a
/// banded model's bands add up to it), so that both morph schedules frame a model alike.
std::vector<float> base_layers(const std::vector<morph::SceneModel>& models) {
  std::vector<float> xyz;
  for (const morph::SceneModel& m : models) {
    const std::size_t per = 3u * static_cast<std::size_t>(m.size()) * static_cast<std::size_t>(m.size());
    for (int p = 0; p < m.num_patches; ++p) {
      const std::size_t first = static_cast<std::size_t>(p) * static_cast<std::size_t>(m.bands) * per;
      const std::size_t at = xyz.size();
      xyz.insert(xyz.end(), m.positions.begin() + static_cast<std::ptrdiff_t>(first),
                 m.positions.begin() + static_cast<std::ptrdiff_t>(first + per));
      for (int b = 1; b < m.bands; ++b)
        for (std::size_t k = 0; k < per; ++k)
          xyz[at + k] += m.positions[first + static_cast<std::size_t>(b) * per + k];
    }
  }
  return xyz;
}

/// Options that can only be checked once the manifest is known: "" or one line for exit code 2.
std::string check_options_against_pack(const Options& opt, const geomip::codec::PackInfo& info) {
  const int models = static_cast<int>(info.models.size());
  if (opt.model >= models)
    return "--model " + std::to_string(opt.model) + " is out of range: the pack has " + std::to_string(models) +
           (models == 1 ? " model (index 0)" : " models (indices 0-" + std::to_string(models - 1) + ")");
  const int finest = info.models[static_cast<std::size_t>(opt.model)].geometry.level;
  if (opt.level > finest)
    return "--level " + std::to_string(opt.level) + " is out of range: model " + std::to_string(opt.model) +
           "'s finest grid level is " + std::to_string(finest);
  if (opt.morph && models < 2)
    return "--morph needs at least 2 models; the pack has 1";
  if (opt.animate && models < 2) return "--animate needs at least 2 models; the pack has 1";
  // A morph between models of different layouts cannot be drawn (the renderer would show the source alone):
  // an option that cannot be honoured is an error, as `geomip morph` says for the same pack.
  auto layout_differs = [&](int a, int b) {
    const auto& ga = info.models[static_cast<std::size_t>(a)].geometry;
    const auto& gb = info.models[static_cast<std::size_t>(b)].geometry;
    return ga.level != gb.level || ga.num_patches != gb.num_patches;
  };
  if (opt.morph && layout_differs(opt.model, (opt.model + 1) % models))
    return "--morph: models " + std::to_string(opt.model) + " and " +
           std::to_string((opt.model + 1) % models) +
           " do not share a patch layout (a consistent pack comes from geomip convert --points)";
  if (opt.animate)
    for (int m = 0; m + 1 < models; ++m)
      if (layout_differs(m, m + 1))
        return "--animate: models " + std::to_string(m) + " and " + std::to_string(m + 1) +
               " do not share a patch layout (a consistent pack comes from geomip convert --points)";
  return {};
}

std::string kb(std::uint64_t bytes) { return std::to_string((bytes + 512) / 1024) + " KB"; }

int run(const Options& opt) {
  const bool headless = opt.frames > 0;
  const bool wavelet = opt.schedule == "wavelet";
  glfwSetErrorCallback([](int, const char* d) { std::cerr << "geomip-view: GLFW: " << d << "\n"; });
  if (!glfwInit()) {
    std::cerr << "geomip-view: cannot initialise GLFW (no display? run under xvfb-run)\n";
    return kExitFailure;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  if (headless) glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(opt.width, opt.height, "geomip-view", nullptr, nullptr);
  if (!window) {
    std::cerr << "geomip-view: cannot create an OpenGL 3.3 core window\n";
    glfwTerminate();
    return kExitFailure;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(headless ? 0 : 1);

  int exit_code = kExitOk;
  bool usage_error = false;  // an option the pack cannot satisfy (--model, --level): exit 2, one line
  {
    Renderer renderer;
    Offscreen target(opt.width, opt.height);
    PackSource source(opt.source,
                      FetchOptions{.limit_rate = opt.limit_rate, .stall_seconds = opt.stall_timeout},
                      morph::DecodeSettings{.bands = wavelet ? opt.bands : 1,
                                            .align = !opt.no_align,
                                            .incremental = !opt.decode_each_prefix,
                                            .up = opt.up.empty() ? '\0' : opt.up[0]});
    Ui ui;
    ui.settings.width = opt.width;
    ui.settings.height = opt.height;
    ui.settings.level = opt.level;
    ui.settings.source = opt.model;
    ui.settings.t = opt.morph.value_or(0.0f);
    ui.settings.schedule = wavelet ? morph::MorphSchedule::kWavelet : morph::MorphSchedule::kLinear;
    ui.settings.checker = opt.checker;
    ui.settings.wireframe = opt.wireframe;
    ui.settings.camera = Camera{opt.yaw, opt.pitch, opt.distance, 35.0f};
    ui.auto_level = !headless && opt.level < 0;
    ui.animate = opt.animate;
    glfwSetWindowUserPointer(window, &ui);
    glfwSetKeyCallback(window, key_callback);
    glfwSetMouseButtonCallback(window, mouse_button);
    glfwSetCursorPosCallback(window, cursor_pos);
    glfwSetScrollCallback(window, scroll);

    const auto start = Clock::now();
    auto last_title = start;
    auto last_frame = start;
    double frame_ms = 0;
    bool have_models = false, first_written = false, checked_options = false;
    std::string timed_out;  // set when headless --timeout ends the wait
    std::uint64_t shown_bytes = 0, total = 0;
    int detail = 0;
    int frames_after_load = 0;
    double bench_ms = 0;
    std::vector<std::uint8_t> last_pixels;

    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      if (!checked_options) {
        if (const geomip::codec::PackInfo* info = source.info()) {
          checked_options = true;
          if (std::string e = check_options_against_pack(opt, *info); !e.empty()) {
            std::cerr << "geomip-view: " << e << "\n";
            usage_error = true;
            break;
          }
        }
      }
      if (auto u = source.take_update()) {
        renderer.set_models(u->models);
        have_models = true;
        shown_bytes = u->bytes_used;
        total = u->total;
        detail = u->models[0].detail_level;
        ui.max_level = renderer.model_level(std::clamp(opt.model, 0, renderer.model_count() - 1));
        // Frame all models together (~70 % of the height for the largest; they are aligned to the first, so a
        // morph keeps one camera) until the user moves the camera or gave --distance.
        if (!opt.distance_given && !ui.camera_moved)
          ui.settings.camera.distance = framing_distance(ui.settings.camera, base_layers(u->models),
                                                         ui.settings.width, ui.settings.height);
        std::cout << "geomip-view: showing " << shown_bytes << " of " << total << " bytes, detail level " << detail
                  << "/" << ui.max_level << "\n";
      }
      const std::string err = geomip::codec::one_line(source.error());  // in the title; printed once, on exit
      const bool loaded = source.done();

      // morph / animate
      RenderSettings s = ui.settings;
      const int n_models = renderer.model_count();
      s.source = std::clamp(opt.model, 0, std::max(n_models - 1, 0));
      if (ui.animate && n_models >= 2) {
        const float dt = headless ? 1.0f / 60.0f : static_cast<float>(frame_ms / 1000.0);
        ui.anim = std::fmod(ui.anim + dt * 0.25f, static_cast<float>(n_models));
        s.source = static_cast<int>(ui.anim) % n_models;
        s.target = (s.source + 1) % n_models;
        s.t = ui.anim - std::floor(ui.anim);
      } else if ((opt.morph || !headless) && n_models >= 2) {
        s.target = (s.source + 1) % n_models;
      }
      if (ui.auto_level && have_models)
        s.level = auto_level(s, ui.max_level, 1);

      const auto t0 = Clock::now();
      target.bind();
      renderer.draw(s);
      if (headless) {
        glFinish();
      } else {
        int fw = 0, fh = 0;
        glfwGetFramebufferSize(window, &fw, &fh);
        target.blit_to_window(fw, fh);
        glfwSwapBuffers(window);
      }
      const auto t1 = Clock::now();
      frame_ms = std::chrono::duration<double, std::milli>(t1 - last_frame).count();
      last_frame = t1;

      if (have_models && !first_written && !opt.first_screenshot.empty()) {
        std::string e;
        if (write_png(opt.first_screenshot, opt.width, opt.height, target.read_rgb(), e)) {
          std::cout << "geomip-view: first screenshot from " << shown_bytes << " of " << total << " bytes\n";
        } else {
          std::cerr << "geomip-view: --first-screenshot: " << geomip::codec::one_line(e) << "\n";
          exit_code = kExitFailure;  // said once; the viewing goes on
        }
        first_written = true;
      }
      if (!headless && t1 - last_title > std::chrono::milliseconds(250)) {
        last_title = t1;
        const std::string title = "geomip-view — level " +
                                  std::to_string(s.level < 0 ? ui.max_level : s.level) +
                                  (ui.auto_level ? " (auto)" : "") + ", detail " + std::to_string(detail) +
                                  " — " + kb(source.received()) + " / " + kb(source.total()) + " — " +
                                  std::to_string(static_cast<int>(frame_ms * 10) / 10.0).substr(0, 5) +
                                  " ms" + (s.target >= 0 ? " — t " + std::to_string(s.t).substr(0, 4) : "") +
                                  (err.empty() ? "" : " — ERROR: " + err);
        glfwSetWindowTitle(window, title.c_str());
      }

      if (headless) {
        if (loaded && have_models) {
          ++frames_after_load;
          bench_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
          if (frames_after_load >= opt.frames) {
            last_pixels = target.read_rgb();
            break;
          }
        } else if (loaded) {
          break;  // the source ended with nothing to show
        } else if (std::chrono::duration<double>(t1 - start).count() > opt.timeout) {
          std::ostringstream o;
          o << "timed out after " << opt.timeout << " s waiting for the pack (" << source.received() << " of "
            << (source.total() ? std::to_string(source.total()) : std::string("?")) << " bytes received)";
          timed_out = o.str();
          // Exit 3 keeps the last complete level shown: it is written too (--screenshot), as for a pack that
          // ends early.
          if (have_models) last_pixels = target.read_rgb();
          break;
        } else if (!have_models) {
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
      }
    }

    if (usage_error) {
      exit_code = kExitBadInput;
    } else if (headless) {
      if (!opt.screenshot.empty() && !last_pixels.empty()) {
        std::string e;
        if (!write_png(opt.screenshot, opt.width, opt.height, last_pixels, e)) {
          if (exit_code != kExitFailure)  // a failed --first-screenshot said its line already
            std::cerr << "geomip-view: --screenshot: " << geomip::codec::one_line(e) << "\n";
          exit_code = kExitFailure;
        }
      }
      if (opt.bench && frames_after_load > 0)
        std::cout << "geomip-view: bench " << opt.width << "x" << opt.height << ", " << renderer.model_count()
                  << " models, level " << (ui.settings.level < 0 ? ui.max_level : ui.settings.level) << ", "
                  << (opt.morph || opt.animate ? (wavelet ? "wavelet morph" : "linear morph") : "no morph") << ": "
                  << bench_ms / frames_after_load << " ms/frame over " << frames_after_load << " frames\n";
      if (opt.bench) {
        const PackSource::DecodeStats d = source.decode_stats();
        std::cout << "geomip-view: decode " << (opt.decode_each_prefix ? "(every prefix from scratch)" : "(incremental)")
                  << ": " << d.updates << " updates, " << d.thread_cpu_ms << " ms CPU of the decode thread, "
                  << d.wall_ms << " ms wall\n";
      }
    }
    // Exactly one line for whatever went wrong.
    std::string err = geomip::codec::one_line(source.error());
    if (err.empty()) err = timed_out;
    if (usage_error) {
      // already said
    } else if (!have_models) {
      std::cerr << "geomip-view: nothing to show"
                << (err.empty() ? " from " + opt.source + " (no geometry arrived)" : " (" + err + ")") << "\n";
      exit_code = kExitBadInput;
    } else if (!source.complete() && exit_code == kExitFailure) {
      // A screenshot that could not be written said its line and set exit 1: exactly one line.
    } else if (!source.complete()) {
      std::cerr << "geomip-view: incomplete stream: kept the level from " << shown_bytes << " of "
                << (total ? total : source.total()) << " bytes" << (err.empty() ? "" : " (" + err + ")") << "\n";
      if (exit_code == kExitOk) exit_code = kExitPartial;
    }
  }
  glfwDestroyWindow(window);
  glfwTerminate();
  return exit_code;
}

}  // namespace

/// A check for options that must be ≥ 0, with a short message (CLI11's own prints the largest double).
static CLI::Validator non_negative(const std::string& what) {
  return CLI::Validator(
      [what](std::string& v) {
        double x = 0;
        if (!CLI::detail::lexical_cast(v, x) || !std::isfinite(x))
          return v + " is not a number (" + what + ")";
        return x >= 0 ? std::string() : v + " is negative (" + what + ")";
      },
      ">= 0");  // ASCII: CLI11 pads its help columns by bytes
}

/// A number that is not NaN or infinite (a NaN camera drew a blank frame and exited 0).
static CLI::Validator finite(const std::string& what) {
  return CLI::Validator(
      [what](std::string& v) {
        double x = 0;
        return CLI::detail::lexical_cast(v, x) && std::isfinite(x) ? std::string()
                                                                   : v + " is not a number (" + what + ")";
      },
      "finite");
}

/// The same for options that must be > 0.
static CLI::Validator positive(const std::string& what) {
  return CLI::Validator(
      [what](std::string& v) {
        double x = 0;
        return CLI::detail::lexical_cast(v, x) && std::isfinite(x) && x > 0
                   ? std::string()
                   : v + " is not a number above 0 (" + what + ")";
      },
      "> 0");
}

int main(int argc, char** argv) {
  Options opt;
  CLI::App app{"geomip-view — progressive viewer of .gip packs (file or http:// URL).\n"
               "Keys: mouse drag orbit, wheel zoom, Up/Down level, L auto level, C checkerboard, W wireframe,\n"
               "Left/Right morph t, Space animate, S linear/wavelet schedule, Q quit.\n"
               "Exit codes: 0 ok, 1 internal failure, 2 bad input or nothing to show, 3 stream failed part-way.\n"
               "Out-of-range --morph/--level/--model are errors (exit 2), never clamped. Nothing read is trusted:\n"
               "a manifest laying out more than the source's real size is read up to that size (exit 3), one over\n"
               "1 GiB is refused (exit 2); HTTP redirects are followed (at most 5).",
               "geomip-view"};
  app.add_option("pack", opt.source, "pack file or http:// URL")->required();
  app.add_option("--level", opt.level,
                 "grid level to draw, 0 … the model's finest (default: finest; interactive: auto); a level beyond "
                 "the model's finest is an error (exit 2) once the manifest is known")
      ->check(non_negative("a grid level"));
  auto* morph_option =
      app.add_option("--morph", opt.morph,
                     "morph time t in [0,1] from --model to the next model (the last model's next is model "
                     "0; outside "
                     "[0,1], or a one-model pack: exit 2)")
          ->check(CLI::Validator(
              [](std::string& v) {
                float t = 0;
                if (!CLI::detail::lexical_cast(v, t) || !std::isfinite(t))
                  return "t = " + v + " is not a number";
                return t >= 0.0f && t <= 1.0f ? std::string() : "t = " + v + " is outside [0, 1]";
              },
              "in [0,1]"));
  app.add_option("--schedule", opt.schedule, "morph schedule")->check(CLI::IsMember({"linear", "wavelet"}));
  app.add_option("--bands", opt.bands, "wavelet bands of the wavelet schedule")->check(CLI::Range(2, 8));
  app.add_option("--model", opt.model,
                 "model index to show (morph source); an index past the pack's models is an error (exit 2) once "
                 "the manifest is known")
      ->check(non_negative("a model index"));
  auto* animate =
      app.add_flag("--animate", opt.animate,
                   "cycle the morph through all models (a one-model pack: exit 2; not with --morph)");
  animate->excludes(morph_option);
  app.add_flag("--no-align", opt.no_align,
               "keep each model in its own frame (default: models 1… are aligned to model 0 by the least-squares "
               "similarity over corresponding samples)");
  app.add_option(
         "--frames", opt.frames,
         "headless: render N frames after loading, then exit (without it the window stays open until Q, "
         "also under xvfb-run)")
      ->check(positive("a frame count"));
  app.add_option("--width", opt.width, "framebuffer width")->check(CLI::Range(16, 8192));
  app.add_option("--height", opt.height, "framebuffer height")->check(CLI::Range(16, 8192));
  // A window left open never writes its last frame: the headless options need --frames (exit 2 otherwise).
  app.add_option("--screenshot", opt.screenshot, "headless (needs --frames): write the last frame as PNG")
      ->needs("--frames");
  app.add_option("--first-screenshot", opt.first_screenshot,
                 "write the first frame that shows a model (streaming: the coarsest level) as PNG");
  app.add_flag("--bench", opt.bench, "headless (needs --frames): print ms/frame and the decoding's time")
      ->needs("--frames");
  app.add_flag("--decode-each-prefix", opt.decode_each_prefix,
               "for measurements: decode every received prefix from scratch (the viewer before incremental "
               "decoding) instead of each byte once");
  app.add_flag("--checker", opt.checker, "checkerboard texture in parameter space");
  app.add_flag("--wireframe", opt.wireframe, "wireframe");
  app.add_option("--limit-rate", opt.limit_rate,
                 "download (or read) at most this many bytes per second (default 0: no limit)")
      ->check(non_negative("bytes per second"));
  app.add_option("--stall-timeout", opt.stall_timeout,
                 "HTTP: a connection that sends nothing for this many seconds is an error (default 20; under "
                 "--limit-rate at least two of the limit's waits)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{86400}));
  app.add_option("--timeout", opt.timeout, "headless: seconds to wait for the pack")->check(non_negative("seconds"));
  app.add_option(
         "--up", opt.up,
         "the models' up axis in their own units, shown upright whatever the pack's frame says (z for "
         "z-up data such as the horse); default: the frame `geomip convert --up` stored in the pack")
      ->check(CLI::IsMember({"x", "y", "z"}));
  app.add_option("--yaw", opt.yaw, "camera yaw (radians)")->check(finite("radians"));
  app.add_option("--pitch", opt.pitch, "camera pitch (radians)")->check(finite("radians"));
  app.add_option(
         "--distance", opt.distance,
         "camera distance (normalized units); default: the models fill about 70 % of the frame height")
      ->check(positive("normalized units"));
  try {
    app.parse(argc, argv);
    opt.distance_given = app.count("--distance") > 0;
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {  // one line, as every other error
    std::cerr << "geomip-view: " << geomip::codec::one_line(e.what()) << " (see --help)\n";
    return kExitBadInput;
  }
  // The outputs before any work: a directory that does not exist is said now (exit 2), not after the
  // rendering.
  for (const auto& [flag, path] :
       {std::pair<const char*, const std::string*>{"--screenshot", &opt.screenshot},
        {"--first-screenshot", &opt.first_screenshot}}) {
    std::string e;
    if (app.count(flag) > 0 && !check_png_output(*path, e)) {
      std::cerr << "geomip-view: " << flag << ": " << geomip::codec::one_line(e) << "\n";
      return kExitBadInput;
    }
    // The pack itself (a local file) under any name: the screenshot would replace it.
    std::error_code ec;
    if (app.count(flag) > 0 && std::filesystem::exists(*path, ec) &&
        std::filesystem::exists(opt.source, ec) && std::filesystem::equivalent(*path, opt.source, ec)) {
      std::cerr << "geomip-view: " << flag << ": " << geomip::codec::one_line(*path) << " is the pack "
                << geomip::codec::one_line(opt.source) << ": writing it would destroy the pack\n";
      return kExitBadInput;
    }
  }
  try {
    return run(opt);
  } catch (const std::exception& e) {
    std::cerr << "geomip-view: " << geomip::codec::one_line(e.what()) << "\n";
    return kExitFailure;
  }
}
