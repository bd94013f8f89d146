#include "harness/render/render_results.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/output/exporters.hpp"
#include "harness/run/process.hpp"
#include "harness/record/files.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

struct Job {
  std::string key;  // trial id ("" for a run directory)
  fs::path snapshot, pov, png;
  std::string scene_spec;
  std::vector<std::string> scene_params;
  std::string leaf_obj;  // the trial's custom leaf ("" : the default shape)
  bool frame = false;    // a growth frame
  int turn = -1;         // a turntable frame: its number
  fs::path trial_dir;    // where the trial's plant.gbplant is, and its decal images
  RenderResult result;
};

// The frames of a trial directory, in step order (their names, step_NNNNNN.gbplant, sort by step). Only
// snapshots: the images their decals name end in .png.
std::vector<fs::path> frame_snapshots(const fs::path& trial_dir) {
  std::vector<fs::path> out;
  const fs::path d = trial_dir / "frames";
  if (!fs::is_directory(d)) return out;
  for (const auto& e : fs::directory_iterator(d))
    if (e.path().extension() == ".gbplant") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// The rendered frames, and only they: a frame's snapshot is step_NNNNNN.gbplant (six digits, as the trial
// names it, so names sort in step order) and renders to step_NNNNNN.png, while the images its decals name
// sit beside it as step_NNNNNN.IMAGE (step_000010.texture.png), which this must not match.
constexpr const char* kFrameGlob = "frames/step_[0-9][0-9][0-9][0-9][0-9][0-9].png";

// A video made from numbered frames: the frames' glob (relative to the trial directory), the file it
// writes there, ffmpeg's log beside it, and its frame rate.
struct Video {
  const char* glob;
  const char* file;
  const char* log;
  const char* fps;
};
// The growth animation; the turntable, whose frames are turntable/frame_NNNN.png (four digits, so names
// sort in turn order).
constexpr Video kGrowthVideo{kFrameGlob, "animation.mp4", "animation.log", "12"};
constexpr Video kTurntableVideo{"turntable/frame_[0-9][0-9][0-9][0-9].png", "turntable.mp4", "turntable.log", "24"};

// ffmpeg: the rendered frames (video.glob) to video.file (H.264, even dimensions). Returns a record of the
// attempt.
AnimationRecord make_video(const fs::path& trial_dir, std::size_t frames, const Video& video) {
  AnimationRecord a;
  a.frames = frames;
  a.frame_pattern = video.glob;
  const std::string ffmpeg = find_program("ffmpeg");
  if (ffmpeg.empty()) {
    a.status = "no_ffmpeg";
    a.message = "ffmpeg is not installed: the numbered PNG frames are the animation";
    return a;
  }
  // `-f image2`: ffmpeg picks its image reader from the name only when the name holds *, ? or {, and
  // the globs have none of them.
  std::vector<std::string> args = {ffmpeg,
                                   "-y",
                                   "-loglevel",
                                   "error",
                                   "-framerate",
                                   video.fps,
                                   "-f",
                                   "image2",
                                   "-pattern_type",
                                   "glob",
                                   "-i",
                                   video.glob,
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-pix_fmt",
                                   "yuv420p",
                                   video.file};
  const ChildResult cr = run_program(args, trial_dir.string(), {600.0, 0}, (trial_dir / video.log).string());
  if (cr.exit_code == 0 && fs::exists(trial_dir / video.file)) {
    a.status = "ok";
    a.file = video.file;
    a.bytes = fs::file_size(trial_dir / video.file);
  } else {
    a.status = "failed";
    a.message = fmt::format("ffmpeg failed (exit {}); see {}", cr.exit_code, (trial_dir / video.log).string());
  }
  return a;
}

// Removes an earlier turntable's frames (their images, scene files and logs) from trial_dir/turntable, so
// a shorter turntable does not pick up its tail.
void clear_turntable(const fs::path& trial_dir) {
  const fs::path d = trial_dir / "turntable";
  if (!fs::is_directory(d)) return;
  std::vector<fs::path> old;
  for (const auto& e : fs::directory_iterator(d))
    if (e.path().filename().string().rfind("frame_", 0) == 0) old.push_back(e.path());
  for (const auto& p : old) fs::remove(p);
}

// A trial's render and its frames' (when it kept a plant snapshot); false when it has none. Each render
// sits beside its snapshot, so the decal images the snapshot names (relative to its directory) are in
// the directory POV-Ray runs in and reads them from.
// A turntable of `turntable` frames (turntable/frame_NNNN.png, rendered with POV-Ray in the trial's
// directory, where the plant's decal images are) follows, when asked.
bool add_trial(std::vector<Job>& jobs, const std::string& key, const fs::path& tdir, const std::string& scene_spec,
               const std::vector<std::string>& scene_params, const std::string& leaf_obj, int turntable) {
  if (!fs::exists(tdir / "plant.gbplant")) return false;
  jobs.push_back({key,
                  tdir / "plant.gbplant",
                  tdir / "render.pov",
                  tdir / "render.png",
                  scene_spec,
                  scene_params,
                  leaf_obj,
                  false,
                  -1,
                  tdir,
                  {}});
  for (const auto& f : frame_snapshots(tdir)) {
    fs::path png = f;
    png.replace_extension(".png");
    fs::path pov = f;
    pov.replace_extension(".pov");
    jobs.push_back({key, f, pov, png, scene_spec, scene_params, leaf_obj, true, -1, tdir, {}});
  }
  if (turntable > 0) clear_turntable(tdir);
  for (int k = 0; k < turntable; ++k) {
    const fs::path base = tdir / "turntable" / fmt::format("frame_{:04d}", k);
    jobs.push_back({key,
                    tdir / "plant.gbplant",
                    fs::path(base).concat(".pov"),
                    fs::path(base).concat(".png"),
                    scene_spec,
                    scene_params,
                    leaf_obj,
                    false,
                    k,
                    tdir,
                    {}});
  }
  return true;
}

// A render's progress line: "render NAME: 45% after 30 s, ETA 37 s", redrawn in place on a terminal, and
// every half minute into a log.
std::function<void(double, double)> progress_printer(std::string name, bool tty, std::mutex& print_mutex) {
  return [name = std::move(name), tty, &print_mutex, last = -1e9](double done, double el) mutable {
    if (!tty && el - last < 30.0) return;
    last = el;
    std::lock_guard lock(print_mutex);
    const std::string line = done < 0.0 ? fmt::format("render {}: preparing ({:.0f} s)", name, el)
                                        : fmt::format("render {}: {:.0f}% after {:.0f} s, ETA {:.0f} s", name,
                                                      100.0 * done, el, done > 0.0 ? el * (1.0 - done) / done : 0.0);
    if (tty)
      fmt::print(stderr, "\r{:<110}", line.substr(0, 110));
    else
      fmt::print(stderr, "{}\n", line);
  };
}

// Renders every job with `workers` POV-Ray processes at once, each scene loaded and each leaf read once.
void render_jobs(std::vector<Job>& jobs, int workers, const RenderOptions& ro, const RenderDirOptions& o) {
  std::mutex scene_mutex, print_mutex;
  std::map<std::string, std::shared_ptr<const Scene>> scenes;
  auto scene_for = [&](const Job& j) {
    std::lock_guard lock(scene_mutex);
    std::string key = j.scene_spec;
    for (const auto& p : j.scene_params) key += "\n" + p;
    auto& s = scenes[key];
    if (!s) s = std::make_shared<const Scene>(load_scene(j.scene_spec, j.scene_params));
    return s;
  };
  // Render options per custom leaf: each OBJ is read once, not once per trial and frame.
  std::map<std::string, RenderOptions> leaf_options;
  auto options_for = [&](const Job& j) {
    std::lock_guard lock(scene_mutex);
    const auto it = leaf_options.find(j.leaf_obj);
    if (it != leaf_options.end()) return it->second;
    RenderOptions jro = ro;
    jro.mesher.leaf_obj = j.leaf_obj;
    jro.mesher = with_leaf_mesh(jro.mesher);
    return leaf_options.emplace(j.leaf_obj, jro).first->second;
  };
  // A growth frame is framed as the grown plant is, so the animation's camera stands still.
  std::map<fs::path, Aabb> grown;
  auto job_options = [&](const Job& j, const Scene& scene) {
    RenderOptions jo = options_for(j);
    if (j.turn >= 0) {
      jo.turn = j.turn;
      jo.turns = o.turntable;
    }
    if (!j.frame) return jo;
    {
      std::lock_guard lock(scene_mutex);
      if (const auto it = grown.find(j.trial_dir); it != grown.end()) {
        jo.subject = it->second;
        return jo;
      }
    }
    jo.subject = render_view(scene, read_plant_snapshot((j.trial_dir / "plant.gbplant").string()), jo).subject;
    std::lock_guard lock(scene_mutex);
    grown.emplace(j.trial_dir, jo.subject);
    return jo;
  };
  std::atomic<std::size_t> next{0}, done{0};
  const bool tty = isatty(STDERR_FILENO) != 0 && !o.quiet;
  const auto t0 = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < jobs.size();) {
      Job& j = jobs[k];
      try {
        const auto scene = scene_for(j);
        const Plant plant = read_plant_snapshot(j.snapshot.string());
        RenderOptions jo = job_options(j, *scene);
        // A paper render can take minutes: it says how far it is, with an estimate of the time left.
        if (!o.quiet && o.render.quality == RenderQuality::Paper)
          jo.progress = progress_printer(j.key.empty() ? j.png.filename().string() : j.key, tty, print_mutex);
        // A turntable frame runs POV-Ray in the trial's directory, where the decal images are.
        j.result = render_plant(*scene, plant, j.pov.string(), j.png.string(), jo,
                                j.turn >= 0 ? j.trial_dir.string() : std::string());
      } catch (const std::exception& e) {
        j.result.status = "failed";
        j.result.message = e.what();
      }
      const std::size_t n = ++done;
      if (!o.quiet) {
        std::lock_guard lock(print_mutex);
        const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const std::string rel = j.png.lexically_relative(j.trial_dir).string();
        const std::string what = j.key.empty() ? rel : j.frame || j.turn >= 0 ? j.key + "/" + rel : j.key;
        const std::string line =
            fmt::format("render [{}/{}] {}: {} ({:.1f} s), ETA {:.0f} s", n, jobs.size(), what, j.result.status,
                        j.result.wall_s, el / static_cast<double>(n) * static_cast<double>(jobs.size() - n));
        if (tty)
          fmt::print(stderr, "\r{:<110}", line.substr(0, 110));
        else
          fmt::print(stderr, "{}\n", line);
        if (!j.result.ok()) fmt::print(stderr, "{}growbench: render failed: {}\n", tty ? "\n" : "", j.result.message);
      }
    }
  };
  // Renders report as they finish; say at once how many there are, since the first can take a while.
  std::fflush(stdout);  // what the caller printed (a suite's summary) comes before the progress lines
  if (!o.quiet)
    fmt::print(stderr, "render: {} image{} at {} quality, {} POV-Ray process{} at once\n", jobs.size(),
               jobs.size() == 1 ? "" : "s", to_string(o.render.quality), workers, workers == 1 ? "" : "es");
  std::vector<std::thread> pool;
  for (int i = 0; i < workers; ++i) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
  if (tty) fmt::print(stderr, "\r{:<110}\r", "");
}

// A render as its record keeps it, with paths relative to the results (or run) directory.
RenderRecord render_record(const Job& j, const RenderOptions& ro, const fs::path& dir) {
  auto rel = [&](const fs::path& p) { return p.lexically_relative(dir).string(); };
  const RenderResult& r = j.result;
  RenderRecord rr;
  rr.status = r.status;
  if (!r.message.empty()) rr.message = r.message;
  rr.warnings = r.warnings;
  rr.png = rel(j.png);
  rr.pov = rel(j.pov);
  rr.log = rel(fs::path(r.log));
  rr.width = r.width;
  rr.height = r.height;
  rr.pov_bytes = r.pov_bytes;
  rr.write_s = r.write_s;
  rr.wall_s = r.wall_s;
  rr.cpu_s = r.cpu_s;
  rr.quality = to_string(ro.quality);
  rr.branches = ro.branches;
  if (ro.branches == "cones") rr.min_branch_px = ro.min_branch_px;
  rr.threads = ro.threads;
  if (!r.camera.empty()) {
    rr.camera = r.camera;
    rr.scene_extent = r.scene_extent;
    rr.in_frame_share = r.seen.in_frame;
    rr.visible_share = r.seen.visible;
  }
  if (r.plant_pixel_share >= 0.0) rr.plant_pixel_share = r.plant_pixel_share;
  rr.backdrop = to_string(ro.backdrop);
  rr.dof = ro.dof;
  return rr;
}

// Where renders and animations are recorded: each trial of a suite's results, or the one run's record.
struct RenderTargets {
  ResultsFile* results = nullptr;                  // a suite
  TrialRecord* record = nullptr;                   // a run
  std::map<std::string, std::size_t> trial_index;  // id -> index in results->trials
  Media& media(const std::string& key) { return results ? results->trials[trial_index.at(key)].media : record->media; }
  void set(const std::string& key, RenderRecord r) { media(key).render = std::move(r); }
  void set(const std::string& key, AnimationRecord a) { media(key).animation = std::move(a); }
  void set_turntable(const std::string& key, AnimationRecord a) { media(key).turntable = std::move(a); }
};

// The frames of one kind (growth or turntable) per trial, and the first failure among them.
struct FrameTally {
  std::map<std::string, std::size_t> count;
  std::map<std::string, std::string> failure;
  void add(const Job& j) {
    ++count[j.key];
    if (!j.result.ok() && !failure.count(j.key)) failure[j.key] = j.result.message;
  }
};

// Each trial's video from its frames (none when one of them failed), recorded by `set`.
template <class Set>
void make_videos(const FrameTally& tally, const Video& video, const char* what, const fs::path& dir, bool suite,
                 bool quiet, Set&& set) {
  for (const auto& [key, n] : tally.count) {
    const fs::path tdir = suite ? dir / "trials" / key : dir;
    AnimationRecord a;
    if (const auto failed = tally.failure.find(key); failed != tally.failure.end()) {
      a.status = "failed";
      a.frames = n;
      a.message = failed->second;
    } else {
      a = make_video(tdir, n, video);
    }
    if (suite && a.file) a.file = (tdir / *a.file).lexically_relative(dir).string();
    if (!quiet) fmt::print(stderr, "{} {}: {} frames, {}\n", what, key.empty() ? dir.string() : key, n, a.status);
    set(key, std::move(a));
  }
}

// Records every render, makes each trial's animation from its frames and its turntable video; the tally
// into `summary`.
void record_renders(const std::vector<Job>& jobs, const RenderOptions& ro, const fs::path& dir,
                    const RenderDirOptions& o, RenderTargets& targets, RenderSummary& summary) {
  const bool suite = targets.results != nullptr;
  FrameTally growth, turntable;
  for (const auto& j : jobs) {
    j.result.ok() ? ++summary.ok : ++summary.failed;
    summary.warnings += j.result.warnings.size();
    summary.povray_s += j.result.wall_s;
    if (j.frame)
      growth.add(j);
    else if (j.turn >= 0)
      turntable.add(j);
    else
      targets.set(j.key, render_record(j, ro, dir));
  }
  summary.renders = summary.ok + summary.failed;
  make_videos(growth, kGrowthVideo, "animation", dir, suite, o.quiet,
              [&](const std::string& key, AnimationRecord a) { targets.set(key, std::move(a)); });
  make_videos(turntable, kTurntableVideo, "turntable", dir, suite, o.quiet,
              [&](const std::string& key, AnimationRecord a) { targets.set_turntable(key, std::move(a)); });
}

// What a suite's grids show: one row per algorithm entry (and sweep value), one column per scene, the
// lowest seed's plant; per cell its image (or a note why there is none), its badge and its trial.
struct GridTable {
  std::vector<std::string> rows, cols;
  std::vector<std::vector<std::string>> cells, notes, badges, trials;
};

GridTable grid_table(const ResultsFile& doc, const fs::path& dir) {
  GridTable g;
  std::map<std::pair<std::string, std::string>, const SuiteCell*> pick;
  for (const auto& t : doc.trials) {
    std::string row = t.label.empty() ? t.algorithm : t.label;
    if (t.sweep.is_object() && !t.sweep.empty()) {
      std::vector<std::string> kv;
      for (const auto& [k, v] : t.sweep.items())
        kv.push_back(fmt::format("{}={}", k, v.is_string() ? v.get<std::string>() : v.dump()));
      row += fmt::format(" {}", fmt::join(kv, " "));
    }
    if (std::find(g.rows.begin(), g.rows.end(), row) == g.rows.end()) g.rows.push_back(row);
    if (std::find(g.cols.begin(), g.cols.end(), t.scene) == g.cols.end()) g.cols.push_back(t.scene);
    const SuiteCell*& p = pick[{row, t.scene}];
    if (!p || t.seed < p->seed) p = &t;
  }
  g.cells.assign(g.rows.size(), std::vector<std::string>(g.cols.size()));
  g.notes = g.badges = g.trials = g.cells;
  for (std::size_t i = 0; i < g.rows.size(); ++i)
    for (std::size_t k = 0; k < g.cols.size(); ++k) {
      const auto it = pick.find({g.rows[i], g.cols[k]});
      if (it == pick.end()) {
        g.notes[i][k] = "not in suite";
        continue;
      }
      const SuiteCell& t = *it->second;
      g.trials[i][k] = t.id;
      if (t.status != "ok")
        g.notes[i][k] = t.status;
      else if (!t.media.render)
        g.notes[i][k] = "no snapshot";
      else if (t.media.render->status != "ok")
        g.notes[i][k] = "render " + t.media.render->status;
      else
        g.cells[i][k] = (dir / t.media.render->png).string();
      // A plant left out of comparisons says so on its image (docs/metrics.md, "Validity").
      if (t.results.plant && t.results.plant->verdict && t.results.plant->verdict->status != "valid")
        g.badges[i][k] =
            t.results.plant->verdict->status == "not_applicable" ? "not applicable" : t.results.plant->verdict->status;
    }
  return g;
}

// The columns [first, last) of a table.
GridTable grid_columns(const GridTable& g, std::size_t first, std::size_t last) {
  GridTable out;
  out.rows = g.rows;
  out.cols.assign(g.cols.begin() + static_cast<std::ptrdiff_t>(first),
                  g.cols.begin() + static_cast<std::ptrdiff_t>(last));
  for (auto* t : {&out.cells, &out.notes, &out.badges, &out.trials}) t->resize(g.rows.size());
  for (std::size_t i = 0; i < g.rows.size(); ++i)
    for (std::size_t k = first; k < last; ++k) {
      out.cells[i].push_back(g.cells[i][k]);
      out.notes[i].push_back(g.notes[i][k]);
      out.badges[i].push_back(g.badges[i][k]);
      out.trials[i].push_back(g.trials[i][k]);
    }
  return out;
}

// IMAGE.map.json beside a grid image: which trial each cell shows and where (the report links them).
void write_grid_map(const fs::path& dir, const std::string& image, const GridLayout& layout,
                    const std::vector<std::string>& trial_of_cell) {
  json cells = json::array();
  for (std::size_t n = 0; n < layout.cells.size() && n < trial_of_cell.size(); ++n)
    if (const GridCell& c = layout.cells[n]; !trial_of_cell[n].empty())
      cells.push_back({{"trial", trial_of_cell[n]}, {"x", c.x}, {"y", c.y}, {"w", c.w}, {"h", c.h}});
  write_file_atomic(
      (dir / (image + ".map.json")).string(),
      json_text({{"image", image}, {"width", layout.width}, {"height", layout.height}, {"cells", cells}}, 1));
}

// A table drawn as one grid image, with its map.
void draw_grid_table(const fs::path& dir, const std::string& image, const std::string& title, const GridTable& g) {
  const GridLayout layout = write_grid((dir / image).string(), title, g.rows, g.cols, g.cells, g.notes, g.badges);
  std::vector<std::string> ids;
  for (const GridCell& c : layout.cells)
    ids.push_back(g.trials[static_cast<std::size_t>(c.row)][static_cast<std::size_t>(c.col)]);
  write_grid_map(dir, image, layout, ids);
}

// The grid in pages of at most kGridPageScenes scenes, each legible at a page's width; none when one page
// holds it all.
std::vector<std::string> write_grid_pages(const fs::path& dir, const std::string& title, const GridTable& g) {
  std::vector<std::string> pages;
  const std::size_t n = (g.cols.size() + kGridPageScenes - 1) / kGridPageScenes;
  for (std::size_t page = 0; n > 1 && page < n; ++page) {
    const std::string name = fmt::format("grid-page-{}.png", page + 1);
    draw_grid_table(dir, name, fmt::format("{} ({} of {})", title, page + 1, n),
                    grid_columns(g, page * g.cols.size() / n, (page + 1) * g.cols.size() / n));
    pages.push_back(name);
  }
  return pages;
}

// Per scene, grid-SCENE.png: its entries side by side, each under its own caption.
std::map<std::string, std::string> write_scene_grids(const fs::path& dir, const GridTable& g) {
  std::map<std::string, std::string> out;
  for (std::size_t k = 0; k < g.cols.size(); ++k) {
    const GridTable col = grid_columns(g, k, k + 1);
    std::vector<std::string> images, notes, badges, ids;
    for (std::size_t i = 0; i < g.rows.size(); ++i) {
      images.push_back(col.cells[i][0]);
      notes.push_back(col.notes[i][0]);
      badges.push_back(col.badges[i][0]);
      ids.push_back(col.trials[i][0]);
    }
    const std::string name = "grid-" + safe_name(g.cols[k]) + ".png";
    const GridLayout layout = write_captioned_grid((dir / name).string(), fmt::format("{} (lowest seed)", g.cols[k]),
                                                   g.rows, images, notes, badges);
    write_grid_map(dir, name, layout, ids);
    out[g.cols[k]] = name;
  }
  return out;
}

// grid.png (the whole suite), its pages and the per-scene grids, each with its map. Failures to write them
// are recorded in `summary`, never fatal.
void write_grids(const ResultsFile& doc, const fs::path& dir, const RenderOptions& ro, RenderSummary& summary) {
  const GridTable g = grid_table(doc, dir);
  const std::string title = fmt::format("growbench suite '{}': algorithm x scene (lowest seed), POV-Ray {}",
                                        doc.suite.name, to_string(ro.quality));
  try {
    draw_grid_table(dir, "grid.png", title, g);
    summary.grid = "grid.png";
    if (std::vector<std::string> pages = write_grid_pages(dir, title, g); !pages.empty()) summary.grid_pages = pages;
    summary.grid_per_scene = write_scene_grids(dir, g);
  } catch (const std::exception& e) {
    summary.grid_error = e.what();
    fmt::print(stderr, "growbench: {}\n", e.what());
  }
}

}  // namespace

RenderSummary render_directory_record(const std::string& dir_arg, const RenderDirOptions& o) {
  const fs::path dir(dir_arg);
  check_render_options(o.render);
  if (o.turntable < 0) throw InputError(fmt::format("--turntable {}: expected a number of frames >= 1", o.turntable));
  const bool suite = fs::exists(dir / "results.json");
  if (!suite && !fs::exists(dir / "record.json"))
    throw InputError(
        fmt::format("{}: neither a suite results directory (results.json) nor a run directory (record.json)", dir_arg));
  // Read, rendered and written back under the lock: no suite can rewrite what this render read.
  const FolderLock lock = FolderLock::take(dir_arg, "render");
  ResultsFile results;
  TrialRecord record;
  RenderTargets targets;
  std::vector<Job> jobs;
  std::size_t skipped = 0;
  if (suite) {
    results = read_results((dir / "results.json").string());
    targets.results = &results;
    for (std::size_t i = 0; i < results.trials.size(); ++i) {
      const SuiteCell& t = results.trials[i];
      targets.trial_index[t.id] = i;
      if (!add_trial(jobs, t.id, dir / "trials" / t.id, t.spec.scene.empty() ? t.scene_spec : t.spec.scene,
                     t.spec.scene_params, t.spec.leaf_obj, o.turntable))
        ++skipped;
    }
  } else {
    record = read_trial_record((dir / "record.json").string());
    targets.record = &record;
    if (!add_trial(jobs, "", dir, record.scene.spec, record.scene.params, record.leaf_obj.value_or(""), o.turntable))
      throw InputError(
          fmt::format("{}: no plant.gbplant to render (written by growbench run and suite trials)", dir_arg));
  }

  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int workers = std::max(1, std::min<int>(o.jobs > 0 ? o.jobs : cores, static_cast<int>(jobs.size())));
  RenderOptions ro = o.render;
  ro.threads = std::max(1, cores / workers);
  if (!jobs.empty() && find_povray().empty())
    throw InputError("povray is not installed: run scripts/install-deps (Debian's povray package) and render again");
  const auto t0 = std::chrono::steady_clock::now();
  render_jobs(jobs, workers, ro, o);
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  RenderSummary summary;
  summary.quality = to_string(ro.quality);
  summary.branches = ro.branches;
  summary.width = render_width(ro);
  summary.height = render_height(ro);
  summary.povray = povray_version();
  summary.jobs = workers;
  summary.threads_per_render = ro.threads;
  summary.skipped_without_snapshot = skipped;
  summary.wall_s = total_s;
  summary.camera = to_string(ro.camera);
  summary.backdrop = to_string(ro.backdrop);
  summary.dof = ro.dof;
  if (o.turntable > 0) summary.turntable = static_cast<std::uint64_t>(o.turntable);
  record_renders(jobs, ro, dir, o, targets, summary);
  if (suite) {
    write_grids(results, dir, ro, summary);
    results.renders = summary;
    write_file_atomic((dir / "results.json").string(), json_text(to_json(results), 1));
  } else {
    write_file_atomic((dir / "record.json").string(), json_text(to_json(record), 2));
  }
  return summary;
}

}  // namespace growbench
