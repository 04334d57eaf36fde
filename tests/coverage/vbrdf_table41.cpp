// vbrdf_table41: the thesis's Table 4.1 experiment on a dense candidate set (acquisition_sim.h).
// Every photo of the given projects is a candidate (they must share one viewpoint and one mesh;
// e.g. a scene's project.mlp plus its heldout/project.mlp); each project's lights come from the
// newest .lp beside it that covers its rasters. From several start photos, counts the photos each
// strategy needs until full coverage and times the decisions.
//   vbrdf_table41 --project P.mlp [--project P2.mlp ...] [--name NAME] [--starts K | --start I]
//                 [--random-runs R] [--brute-force] [--csv out.csv] [--visibility auto|gl|cpu]
//                 [--ts X] [--td X] [--min-elevation DEG]
//                 [--require-full] [--max-extra-vs-brute X] [--require-better-than-random]
// Checks (exit status 1 when one fails): --require-full: the binned strategy reaches full coverage
// from every start; --max-extra-vs-brute X: binned needs at most X more photos than the brute-force
// suggestion on average; --require-better-than-random: binned needs fewer photos than random.
// Exit status 2: bad input.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tool_errors.h"
#include "tools/acquisition_sim.h"
#include "run/coverage_run.h"
#include "base/errors.h"
#include "tools/mesh_io.h"
#include "osmesa_context.h"
#include "inputs/project.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
struct Options {
  std::vector<std::string> projects;
  std::string name, csv;
  int starts = 10, start = -1, random_runs = 20;
  float tolerance = 0, failure_cone = 20;
  bool brute = false, require_full = false, require_better_than_random = false, trace = false, both = false;
  double max_extra_vs_brute = -1;
  CoverageSettings coverage = vbrdf::test::thesis_coverage_settings();  // gather + visibility + suggestion settings
};

int usage() {
  std::cerr << "usage: vbrdf_table41 --project P.mlp [--project P2.mlp ...] [--name NAME] [--starts K | --start I]\n"
               "                     [--random-runs R] [--brute-force] [--csv out.csv] [--visibility auto|gl|cpu]\n"
               "                     [--ts X] [--td X] [--min-elevation DEG] [--require-full]\n"
               "                     [--max-extra-vs-brute X] [--require-better-than-random]\n";
  return 2;
}

bool parse(int argc, char **argv, Options &o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--project") o.projects.push_back(next());
    else if (a == "--name") o.name = next();
    else if (a == "--csv") o.csv = next();
    else if (a == "--starts") o.starts = std::stoi(next());
    else if (a == "--start") o.start = std::stoi(next());
    else if (a == "--random-runs") o.random_runs = std::stoi(next());
    else if (a == "--brute-force") o.brute = true;
    else if (a == "--trace") o.trace = true;
    else if (a == "--tolerance") o.tolerance = std::stof(next());
    else if (a == "--failure-cone") o.failure_cone = std::stof(next());
    else if (a == "--both") o.both = true;
    else if (a == "--require-full") o.require_full = true;
    else if (a == "--require-better-than-random") o.require_better_than_random = true;
    else if (a == "--max-extra-vs-brute") o.max_extra_vs_brute = std::stod(next());
    else if (a == "--ts") o.coverage.gather.specular_threshold = std::stof(next());
    else if (a == "--td") o.coverage.gather.diffuse_threshold = std::stof(next());
    else if (a == "--min-elevation") o.coverage.suggest.min_elevation_deg = std::stof(next());
    else if (a == "--visibility") {
      const std::string v = next();
      o.coverage.visibility_choice = v == "gl" ? VisibilityChoice::GL : v == "cpu" ? VisibilityChoice::CPU : VisibilityChoice::Auto;
    } else return false;
  }
  return !o.projects.empty() && o.starts > 0 && o.random_runs >= 0;
}

// Every raster of every project with its world light direction.
void load_candidates(const Options &o, MeshData &mesh, std::vector<Raster> &rasters,
                     std::vector<std::array<float, 3>> &lights) {
  for (size_t i = 0; i < o.projects.size(); ++i) {
    const Project p = read_project(o.projects[i]);
    if (i == 0) mesh = load_mesh_ply(p.mesh_path);
    else if (load_mesh_ply(p.mesh_path).positions.size() != mesh.positions.size())
      throw InputError("Project '" + o.projects[i] + "' has another mesh than '" + o.projects[0] + "'.");
    const std::string lp = find_default_light_file(p.rasters, p.project_path);
    if (lp.empty()) throw InputError("No .lp beside '" + o.projects[i] + "' has an entry for each of its rasters.");
    const auto l = lights_for_rasters(p.rasters, lp);
    rasters.insert(rasters.end(), p.rasters.begin(), p.rasters.end());
    lights.insert(lights.end(), l.begin(), l.end());
  }
}

struct Stats {
  double mean = 0, sd = 0, min = 0, max = 0;
  size_t n = 0;
};
Stats stats_of(const std::vector<double> &x) {
  Stats s;
  s.n = x.size();
  if (x.empty()) return s;
  s.min = s.max = x[0];
  for (double v : x) s.mean += v, s.min = std::min(s.min, v), s.max = std::max(s.max, v);
  s.mean /= double(x.size());
  for (double v : x) s.sd += (v - s.mean) * (v - s.mean);
  s.sd = x.size() > 1 ? std::sqrt(s.sd / double(x.size() - 1)) : 0;
  return s;
}

struct Summary {
  std::vector<double> diffuse, full, p95, p99, per_choice, max_choice;
  size_t runs = 0, reached = 0, left = 0;
};

// Photos taken when at most (1 - fraction) of the targets were still uncovered (0: never).
size_t photos_to(const SimRun &run, double fraction) {
  const double targets = double(run.target_diffuse + run.target_specular);
  for (size_t i = 0; i < run.uncovered.size(); ++i)
    if (double(run.uncovered[i]) <= (1 - fraction) * targets + 1e-9) return i + 1;
  return 0;
}

void print_row(const char *name, const Summary &s) {
  const Stats d = stats_of(s.diffuse), f = stats_of(s.full), c = stats_of(s.per_choice), m = stats_of(s.max_choice);
  std::printf("%-26s %5zu/%-5zu %6.1f %6.1f %6.1f %4.1f %3.0f-%-3.0f %6.1f %4.1f %3.0f-%-3.0f %9.4f %8.4f %5zu\n", name,
              s.reached, s.runs, stats_of(s.p95).mean, stats_of(s.p99).mean, d.mean, d.sd, d.min, d.max, f.mean, f.sd,
              f.min, f.max, c.mean, m.max, s.left);
}

std::string order_text(const std::vector<size_t> &order) {
  std::string out;
  for (size_t i = 0; i < order.size(); ++i) out += (i ? ";" : "") + std::to_string(order[i]);
  return out;
}
} // namespace

int main(int argc, char **argv) {
  Options o;
  try {
    if (!parse(argc, argv, o)) return usage();
  } catch (const std::exception &) {
    return usage();
  }
  if (o.name.empty()) o.name = o.projects.front();
  const LogFn log = [](const std::string &line) { std::cout << line << "\n"; };
  return test::run_tool([&]() -> int {
    MeshData mesh;
    std::vector<Raster> rasters;
    std::vector<std::array<float, 3>> lights;
    load_candidates(o, mesh, rasters, lights);
    std::unique_ptr<test::OsMesaContext> gl;
    std::function<void *(const char *)> get_proc;
    if (o.coverage.visibility_choice != VisibilityChoice::CPU) {
      try {
        gl.reset(new test::OsMesaContext());
        get_proc = gl->get_proc_address();
      } catch (const std::exception &e) {
        log(std::string("OSMesa context unavailable: ") + e.what());
      }
    }
    const MeshView view = mesh.view();
    auto visibility = make_visibility_backend(view, o.coverage.visibility_choice, o.coverage.visibility, get_proc, log);
    const auto t0 = std::chrono::steady_clock::now();
    const CandidateSet set = gather_candidates(view, rasters, lights, *visibility, o.coverage.gather);
    const double gather_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    SimSettings sim;
    sim.suggest = o.coverage.suggest;
    sim.tolerance_deg = o.tolerance;
    sim.failure_cone_deg = o.failure_cone;
    sim.goal = o.both ? SimGoal::Both : SimGoal::DiffuseThenSpecular;
    sim.suggest.specular_threshold = o.coverage.gather.specular_threshold;
    sim.suggest.diffuse_threshold = o.coverage.gather.diffuse_threshold;
    std::vector<size_t> starts;
    if (o.start >= 0) starts.push_back(size_t(o.start));
    else
      for (int k = 0; k < o.starts && size_t(k) < set.size(); ++k)
        starts.push_back(size_t(k) * set.size() / size_t(std::min<size_t>(size_t(o.starts), set.size())));

    std::vector<SimStrategy> strategies = {SimStrategy::Binned, SimStrategy::Predicted, SimStrategy::Oracle};
    if (o.brute) strategies.insert(strategies.begin() + 1, SimStrategy::BruteForce);
    if (o.random_runs > 0) strategies.push_back(SimStrategy::Random);
    std::map<int, Summary> summary;
    std::ofstream csv;
    if (!o.csv.empty()) {
      csv.open(o.csv);
      csv << "scene,strategy,start,seed,photos_95,photos_99,photos_diffuse,photos_full,left_diffuse,left_specular,choices,seconds,"
             "seconds_max_choice,target_diffuse,target_specular,order\n";
    }
    size_t target_d = 0, target_s = 0;
    for (size_t start : starts)
      for (SimStrategy strategy : strategies) {
        const int runs = strategy == SimStrategy::Random ? o.random_runs : 1;
        for (int rep = 0; rep < runs; ++rep) {
          sim.start = start;
          sim.seed = uint32_t(1000 * start + size_t(rep) + 1);
          const SimRun run = simulate_acquisition(set, strategy, sim);
          target_d = run.target_diffuse, target_s = run.target_specular;
          if (o.trace && !run.predicted.empty()) {
            std::printf("trace %s from %zu:", sim_strategy_name(strategy), start);
            for (size_t k = 0; k < run.predicted.size(); ++k)
              std::printf(" [%zu->%zu %.0fdeg]", run.predicted[k], run.gained[k], double(run.offset_deg[k]));
            std::printf("\n");
          }
          Summary &s = summary[int(strategy)];
          ++s.runs;
          s.left += run.left_diffuse + run.left_specular;
          if (run.photos_diffuse) s.diffuse.push_back(double(run.photos_diffuse));
          if (run.photos_full) s.full.push_back(double(run.photos_full)), ++s.reached;
          if (photos_to(run, 0.95)) s.p95.push_back(double(photos_to(run, 0.95)));
          if (photos_to(run, 0.99)) s.p99.push_back(double(photos_to(run, 0.99)));
          if (run.choices) s.per_choice.push_back(run.seconds / double(run.choices));
          s.max_choice.push_back(run.seconds_max_choice);
          if (csv)
            csv << o.name << "," << sim_strategy_name(strategy) << "," << start << "," << sim.seed << ","
                << photos_to(run, 0.95) << "," << photos_to(run, 0.99) << "," << run.photos_diffuse << "," << run.photos_full << "," << run.left_diffuse << "," << run.left_specular
                << "," << run.choices << "," << run.seconds << "," << run.seconds_max_choice << ","
                << run.target_diffuse << "," << run.target_specular << "," << order_text(run.order) << "\n";
        }
      }
    size_t visible = 0;
    for (uint8_t v : set.visible) visible += v;
    std::printf("scene %s: %zu vertices (%zu seen cleanly from the viewpoint), %zu candidate photos, "
                "targets: %zu diffuse, %zu specular; samples gathered in %.2f s; %zu start photo(s)\n",
                o.name.c_str(), view.vertex_count, visible, set.size(), target_d, target_s, gather_s, starts.size());
    std::printf("%-26s %11s %6s %6s %-20s %-20s %9s %8s %5s\n", "strategy (photos: mean)", "full/runs", "95%",
                "99%", "diffuse (sd, range)", "full (sd, range)", "s/choice", "max s", "left");
    for (SimStrategy strategy : strategies) print_row(sim_strategy_name(strategy), summary[int(strategy)]);

    int status = 0;
    const Summary &binned = summary[int(SimStrategy::Binned)];
    if (o.require_full && binned.reached != binned.runs) {
      std::printf("FAIL: the binned strategy reached full coverage in %zu of %zu runs\n", binned.reached, binned.runs);
      status = 1;
    }
    if (o.max_extra_vs_brute >= 0 && o.brute) {
      const double extra = stats_of(binned.full).mean - stats_of(summary[int(SimStrategy::BruteForce)].full).mean;
      std::printf("binned - brute-force suggestion: %+.2f photos on average (allowed %.2f)\n", extra, o.max_extra_vs_brute);
      if (!(extra <= o.max_extra_vs_brute)) status = 1;
    }
    if (o.require_better_than_random && o.random_runs > 0) {
      const double b = stats_of(binned.full).mean, r = stats_of(summary[int(SimStrategy::Random)].full).mean;
      const size_t random_misses = summary[int(SimStrategy::Random)].runs - summary[int(SimStrategy::Random)].reached;
      std::printf("binned %.2f photos vs random %.2f (random runs short of full coverage: %zu)\n", b, r, random_misses);
      if (!(b < r)) status = 1;
    }
    return status;
  });
}
