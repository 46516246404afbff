// Fluid surface benchmark (issue 14): the surface of 320,000 particles, the paper's Mountain
// size, as a wavy pool of jittered particles 100 x 80 x 40 spacings with 2 % of them thrown up as
// drops. Prints the best of three runs of the isotropic and the anisotropic surface (level set,
// meshing and the vertex values), and appends CSV to bench/results/2core/bench_surface_320k.csv.
//
//   karst_bench_surface [--threads N]
#include "provenance.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/surface/fluid_surface.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

using namespace karst;

int main(int argc, char** argv) {
    int threads = 0;
    for (int a = 1; a + 1 < argc; a += 2)
        if (!std::strcmp(argv[a], "--threads")) threads = std::atoi(argv[a + 1]);
    ThreadLimit limit(threads);
    const Real dx = 0.01, h = 2 * dx;
    std::vector<Vec3> x;
    std::mt19937 rng(1);
    std::uniform_real_distribution<Real> jitter(-0.2 * dx, 0.2 * dx), unit(0, 1);
    for (int i = 0; i < 100; ++i)
        for (int j = 0; j < 80; ++j) {
            const Real top = 0.4 + 0.05 * std::sin(i * 0.15) * std::cos(j * 0.2);
            for (int k = 0; k < 40; ++k) {
                Vec3 p = dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
                p.z() *= top / 0.4;
                if (unit(rng) < 0.02) p.z() += 0.2 * unit(rng) + 0.1;  // a drop in the air
                x.push_back(p + Vec3(jitter(rng), jitter(rng), jitter(rng)));
            }
        }
    const std::vector<Real> volume(x.size(), dx * dx * dx);
    std::vector<Real> speed(x.size());
    for (size_t i = 0; i < x.size(); ++i) speed[i] = x[i].z();

    fmt::print("karst_bench_surface: {} particles, {} threads\n", x.size(),
               ThreadLimit::active_threads());
    const auto file = std::filesystem::path(KARST_SOURCE_DIR) / "bench" / "results" / "2core" /
                      "bench_surface_320k.csv";
    std::ofstream csv = bench::open_results(
        file, "threads,particles,anisotropic,voxel_dx,vertices,triangles,s_surface,s_values");
    for (bool anisotropic : {false, true}) {
        FluidSurfaceOptions options;
        options.voxel = 0.5 * dx;
        options.anisotropic = anisotropic;
        double best = 1e30, best_values = 1e30;
        SurfaceMesh mesh;
        for (int run = 0; run < 3; ++run) {
            Stopwatch watch;
            mesh = colour_field_surface(x, volume, h, options);
            best = std::min(best, watch.seconds());
            Stopwatch values;
            shepard_interpolate(mesh.vertices.x, x, volume, anisotropic ? 2 * h : h, {speed});
            best_values = std::min(best_values, values.seconds());
        }
        fmt::print("  {:11s} surface {:.3f} s, vertex values {:.3f} s: {} vertices, {} triangles\n",
                   anisotropic ? "anisotropic" : "isotropic", best, best_values,
                   mesh.vertex_count(), mesh.triangle_count());
        csv << bench::provenance_fields(KARST_SOURCE_DIR);
        csv << fmt::format("{},{},{},{},{},{},{:.4f},{:.4f}\n", ThreadLimit::active_threads(),
                           x.size(), anisotropic, 0.5, mesh.vertex_count(), mesh.triangle_count(),
                           best, best_values);
    }
    fmt::print("  appended to {}\n", file.string());
}
