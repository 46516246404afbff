// The mesh frames (issue 15): EnSight Gold files read back exactly, the symmetric tensors in
// EnSight's component order, and VTK's own reader (where python3-vtk9 is installed) reads the
// .case file karst writes: a geometry that changes at one step and files read again at others.
#include "karst/io/ensight_writer.hpp"

#include "support/ensight_reader.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace karst {
namespace {

namespace fs = std::filesystem;

PointSet sample_nodes(size_t n, double scale) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    PointSet p;
    std::vector<Real> pressure(n);
    std::vector<Vec3> displacement(n);
    std::vector<Mat3> stress(n);
    for (size_t i = 0; i < n; ++i) {
        p.x.push_back(Vec3(u(rng), u(rng), u(rng)));
        pressure[i] = scale * u(rng);
        displacement[i] = scale * Vec3(u(rng), u(rng), u(rng));
        Mat3 s;
        s << 11, 12, 13, 12, 22, 23, 13, 23, 33;
        stress[i] = scale * s;
    }
    p.add_scalar("pore_pressure", pressure);
    p.add_vector("displacement", displacement);
    p.add_symmetric_tensor("effective_stress", stress);
    return p;
}

std::vector<std::array<Index, 4>> sample_tets(Index n) {
    std::vector<std::array<Index, 4>> tets;
    for (Index t = 0; t + 3 < n; t += 2) tets.push_back({t, t + 1, t + 2, t + 3});
    return tets;
}

TEST(EnsightFrames, GeometryAndVariablesReadBackExactly) {
    const PointSet p = sample_nodes(1000, 1e5);
    const auto tets = sample_tets(1000);
    const test::EnsightGeometry g = test::read_ensight_geometry(ensight_geometry_bytes(p, tets));
    ASSERT_EQ(g.x.size(), p.x.size());
    for (size_t i = 0; i < p.x.size(); ++i)
        for (int d = 0; d < 3; ++d) ASSERT_EQ(g.x[i][d], double(float(p.x[i][d])));
    ASSERT_EQ(g.tets.size(), tets.size());
    for (size_t t = 0; t < tets.size(); ++t)
        for (int k = 0; k < 4; ++k) ASSERT_EQ(g.tets[t][k], tets[t][k] + 1);
    for (const PointArray& a : p.arrays) {
        std::string name;
        const std::vector<double> got = test::read_ensight_variable(
            ensight_variable_bytes(p, a), p.x.size(), a.components, &name);
        EXPECT_EQ(name, a.name);
        // Component-major; tensors as 11 22 33 12 13 23 (VTK's xy yz xz are 12 23 13).
        const int from_vtk[6] = {0, 1, 2, 3, 5, 4};
        for (int c = 0; c < a.components; ++c)
            for (size_t i = 0; i < p.x.size(); ++i) {
                const int k = a.components == 6 ? from_vtk[c] : c;
                ASSERT_EQ(got[c * p.x.size() + i], double(float(a.values[i * a.components + k])))
                    << a.name;
            }
    }
    // The tensor's 13 component is 13 (the sample holds each component's index).
    const std::vector<double> stress =
        test::read_ensight_variable(ensight_variable_bytes(p, p.arrays[2]), p.x.size(), 6);
    EXPECT_EQ(stress[4 * p.x.size()] / stress[0] * 11, 13.0);
}

TEST(EnsightFrames, TheCaseFileGivesEachFileItsOwnTimeSet) {
    const PointSet p = sample_nodes(4, 1);
    const std::string text = ensight_case_bytes(
        "mesh", p, {{0.0, {0, 0, 0, 0}}, {0.5, {0, 1, 0, 1}}, {1.0, {2, 2, 0, 2}}});
    EXPECT_NE(text.find("model: 1 mesh_****.geo\n"), std::string::npos);
    EXPECT_NE(text.find("scalar per node: 2 pore_pressure mesh_pore_pressure_****.ens\n"),
              std::string::npos);
    EXPECT_NE(text.find("vector per node: 3 displacement mesh_displacement_****.ens\n"),
              std::string::npos);
    EXPECT_NE(text.find("tensor symm per node: 4 effective_stress"), std::string::npos);
    EXPECT_NE(text.find("time set: 1\nnumber of steps: 3\nfilename numbers:\n0 0 2\n"),
              std::string::npos);
    EXPECT_NE(text.find("time set: 3\nnumber of steps: 3\nfilename numbers:\n0 0 0\n"),
              std::string::npos);
    EXPECT_NE(text.find("time values:\n0 0.5 1\n"), std::string::npos);
}

/// Runs VTK's EnSight reader (python3-vtk9) on `case_file`; prints, per time step, the point and
/// cell counts and the arrays' first tuples. Empty when VTK is not installed.
std::string read_with_vtk(const fs::path& case_file) {
    if (std::system("/usr/bin/python3 -c 'import vtkmodules.vtkIOEnSight' > /dev/null 2>&1") != 0)
        return "";
    const fs::path script = case_file.parent_path() / "read.py",
                   out = case_file.parent_path() / "out";
    std::ofstream(script) << R"(import sys
from vtkmodules.vtkIOEnSight import vtkGenericEnSightReader
r = vtkGenericEnSightReader(); r.SetCaseFileName(sys.argv[1]); r.UpdateInformation()
times = r.GetTimeSets().GetItem(0)
for s in range(times.GetNumberOfTuples()):
    r.SetTimeValue(times.GetValue(s)); r.Update(); b = r.GetOutput().GetBlock(0)
    print(s, b.GetNumberOfPoints(), b.GetNumberOfCells(), b.GetCellType(0))
    for name in ("pore_pressure", "displacement", "effective_stress"):
        a = b.GetPointData().GetArray(name)
        print(name, " ".join("%.9g" % v for v in a.GetTuple(0)))
)";
    const std::string command = "/usr/bin/python3 " + script.string() + " " + case_file.string() +
                                " > " + out.string() + " 2>&1";
    if (std::system(command.c_str()) != 0) return "VTK failed";
    std::ifstream in(out);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(EnsightFrames, VtkReadsAChangingGeometryAndFilesReadAgain) {
    const fs::path dir = fs::temp_directory_path() / "karst_test_ensight";
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto put = [&](const std::string& name, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << bytes;
    };
    // Step 0: 8 nodes; step 1 reads step 0's files again but a new pressure; step 2: 12 nodes.
    const PointSet small = sample_nodes(8, 1), large = sample_nodes(12, 2);
    PointSet small_later = small;
    small_later.arrays[0].values[0] = 42;
    put(ensight_file("mesh", "", 0), ensight_geometry_bytes(small, sample_tets(8)));
    put(ensight_file("mesh", "", 2), ensight_geometry_bytes(large, sample_tets(12)));
    for (size_t k = 0; k < 3; ++k) {
        const std::string& name = small.arrays[k].name;
        put(ensight_file("mesh", name, 0), ensight_variable_bytes(small, small.arrays[k]));
        put(ensight_file("mesh", name, 2), ensight_variable_bytes(large, large.arrays[k]));
    }
    put(ensight_file("mesh", "pore_pressure", 1),
        ensight_variable_bytes(small_later, small_later.arrays[0]));
    put("mesh.case",
        ensight_case_bytes("mesh", small,
                           {{0.0, {0, 0, 0, 0}}, {0.1, {0, 1, 0, 0}}, {0.2, {2, 2, 2, 2}}}));
    const std::string text = read_with_vtk(dir / "mesh.case");
    if (text.empty()) GTEST_SKIP() << "python3-vtk9 is not installed";
    const std::vector<double>& d = small.arrays[1].values;
    const Vec3 u(d[0], d[1], d[2]);
    const std::string expected = fmt::format(
        "0 8 3 10\npore_pressure {:.9g}\ndisplacement {:.9g} {:.9g} {:.9g}\n"
        "effective_stress 11 22 33 12 23 13\n"
        "1 8 3 10\npore_pressure 42\ndisplacement {:.9g} {:.9g} {:.9g}\n"
        "effective_stress 11 22 33 12 23 13\n"
        "2 12 5 10\n",
        float(small.arrays[0].values[0]), float(u[0]), float(u[1]), float(u[2]), float(u[0]),
        float(u[1]), float(u[2]));
    EXPECT_EQ(text.substr(0, expected.size()), expected) << text;
    EXPECT_NE(text.find("effective_stress 22 44 66 24 46 26\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace karst
