// The VTK frames read back exactly (issue 15): compressed and raw files hold the same values,
// every array is there with its length, and compression makes the frame several times smaller
// where the data allow it.
#include "karst/io/vtk_writer.hpp"

#include "support/vtk_reader.hpp"

#include <gtest/gtest.h>

#include <random>

namespace karst {
namespace {

PointSet sample_points(size_t n) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    PointSet p;
    std::vector<Real> smooth(n), noisy(n);
    std::vector<Vec3> v(n);
    std::vector<std::int64_t> id(n);
    for (size_t i = 0; i < n; ++i) {
        p.x.push_back(Vec3(u(rng), u(rng), u(rng)));
        v[i] = Vec3(u(rng), u(rng), u(rng));
        smooth[i] = 1000.0, noisy[i] = u(rng), id[i] = std::int64_t(3 * i + 1);
    }
    p.add_vector("velocity", v);
    p.add_scalar("density", smooth);
    p.add_scalar("pressure", noisy);
    p.add_integer("id", id);
    return p;
}

void expect_same_as_written(const test::VtkArrays& read, const PointSet& p) {
    ASSERT_EQ(read.arrays.at("Points").size(), 3 * p.x.size());
    for (size_t i = 0; i < p.x.size(); ++i)
        for (int d = 0; d < 3; ++d)
            ASSERT_EQ(read.arrays.at("Points")[3 * i + d], double(float(p.x[i][d])));
    for (const PointArray& a : p.arrays) {
        const std::vector<double>& got = read.arrays.at(a.name);
        ASSERT_EQ(got.size(), a.values.size()) << a.name;
        for (size_t k = 0; k < got.size(); ++k)
            ASSERT_EQ(got[k], a.integer ? a.values[k] : double(float(a.values[k]))) << a.name;
    }
}

TEST(VtkFrames, CompressedAndRawPolyDataReadBackExactly) {
    // Sizes around the zlib block (64 KiB = 16384 floats) and an empty set.
    for (size_t n : {size_t(0), size_t(1), size_t(5461), size_t(16384), size_t(40000)}) {
        const PointSet p = sample_points(n);
        const test::VtkArrays zipped = test::read_vtk_xml(vtp_bytes(p, true));
        const test::VtkArrays raw = test::read_vtk_xml(vtp_bytes(p, false));
        EXPECT_TRUE(zipped.compressed);
        EXPECT_FALSE(raw.compressed);
        expect_same_as_written(zipped, p);
        expect_same_as_written(raw, p);
        EXPECT_EQ(zipped.arrays, raw.arrays) << n;
        ASSERT_EQ(zipped.arrays.at("connectivity").size(), n);
        for (size_t i = 0; i < n; ++i) EXPECT_EQ(zipped.arrays.at("offsets")[i], double(i + 1));
    }
}

}  // namespace
}  // namespace karst
