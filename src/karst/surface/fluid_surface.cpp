#include "karst/surface/fluid_surface.hpp"

#include "karst/core/parallel.hpp"
#include "karst/porous/layering_frame.hpp"
#include "karst/sph/kernels.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <Eigen/LU>

#include <algorithm>
#include <mutex>
#include <numbers>
#include <sstream>

namespace karst {

namespace {

using Leaf = openvdb::FloatTree::LeafNodeType;
constexpr int k_leaf = int(Leaf::DIM);  // voxels per leaf edge
constexpr Real k_smoothing = 0.9;       // Yu-Turk lambda (§7)

/// One particle's kernel W(p) = V det(G) P(|G (p - centre)|), P the cubic spline of support 1.
struct Splat {
    Vec3 centre;
    Mat3 G;
    Real weight;  ///< V det G, 1/m^0
    Vec3 reach;   ///< half-edges of the box holding the kernel's ellipsoid |G r| < 1, m
};

Real unit_cubic(Real q) {
    constexpr Real k = 8 / std::numbers::pi;
    if (q <= 0.5) return k * (6 * q * q * q - 6 * q * q + 1);
    if (q < 1) return 2 * k * (1 - q) * (1 - q) * (1 - q);
    return 0;
}

std::vector<Splat> make_splats(const std::vector<Vec3>& x, const std::vector<Real>& volume, Real h,
                               bool anisotropic) {
    std::vector<Splat> s(x.size());
    if (!anisotropic) {
        parallel_for(Index(x.size()), [&](Index i) {
            s[i] = {x[i], Mat3::Identity() / h, volume[i] / (h * h * h), Vec3::Constant(h)};
        });
        return s;
    }
    const std::vector<PcaFrame> frames = pca_frames(x, h);
    parallel_for(Index(x.size()), [&](Index i) {
        const Mat3 G = pca_kernel_tensor(frames[i], h);
        // r = G^-1 u with |u| < 1: the ellipsoid reaches |row d of G^-1| along axis d.
        const Vec3 reach = G.inverse().rowwise().norm();
        const Vec3 centre = x[i] + k_smoothing * (frames[i].mean - x[i]);
        s[i] = {centre, G, volume[i] * G.determinant(), reach};
    });
    return s;
}

/// Leaf coordinates (leaf origin / k_leaf) packed into one key, ordered z-major.
struct LeafKey {
    static constexpr int k_bits = 21;
    static constexpr std::int64_t k_offset = std::int64_t(1) << (k_bits - 1);
    static std::uint64_t pack(const std::array<int, 3>& c) {
        std::uint64_t key = 0;
        for (int d = 2; d >= 0; --d) key = key << k_bits | std::uint64_t(c[d] + k_offset);
        return key;
    }
    static std::array<int, 3> unpack(std::uint64_t key) {
        std::array<int, 3> c;
        for (int d = 0; d < 3; ++d, key >>= k_bits)
            c[d] = int(std::int64_t(key & ((std::uint64_t(1) << k_bits) - 1)) - k_offset);
        return c;
    }
};

int floor_div(int a, int b) {
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}

/// The splats binned by the leaf holding their centre, bins in key order, splats in index order.
struct Bins {
    std::vector<std::uint64_t> key;
    std::vector<Index> start;  ///< (bins + 1) into order
    std::vector<Index> order;
    std::vector<std::array<int, 6>> voxels;  ///< per bin: the voxel box its kernels reach
    Index find(std::uint64_t k) const {
        const auto it = std::lower_bound(key.begin(), key.end(), k);
        return it != key.end() && *it == k ? Index(it - key.begin()) : -1;
    }
};

std::array<int, 6> voxel_box(const Splat& s, Real voxel) {
    std::array<int, 6> b;
    for (int d = 0; d < 3; ++d) {
        b[d] = int(std::ceil((s.centre[d] - s.reach[d]) / voxel));
        b[d + 3] = int(std::floor((s.centre[d] + s.reach[d]) / voxel));
    }
    return b;
}

Bins bin_splats(const std::vector<Splat>& splats, Real voxel) {
    const Index n = Index(splats.size());
    std::vector<std::pair<std::uint64_t, Index>> keyed(n);
    parallel_for(n, [&](Index i) {
        std::array<int, 3> c;
        for (int d = 0; d < 3; ++d)
            c[d] = floor_div(int(std::lround(splats[i].centre[d] / voxel)), k_leaf);
        keyed[i] = {LeafKey::pack(c), i};
    });
    std::sort(keyed.begin(), keyed.end());
    Bins bins;
    bins.order.resize(n);
    for (Index i = 0; i < n; ++i) {
        if (i == 0 || keyed[i].first != keyed[i - 1].first) {
            bins.key.push_back(keyed[i].first);
            bins.start.push_back(i);
        }
        bins.order[i] = keyed[i].second;
    }
    bins.start.push_back(n);
    bins.voxels.resize(bins.key.size());
    parallel_for(Index(bins.key.size()), [&](Index b) {
        std::array<int, 6> box{INT32_MAX, INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN, INT32_MIN};
        for (Index k = bins.start[b]; k < bins.start[b + 1]; ++k) {
            const std::array<int, 6> s = voxel_box(splats[bins.order[k]], voxel);
            for (int d = 0; d < 3; ++d)
                box[d] = std::min(box[d], s[d]), box[d + 3] = std::max(box[d + 3], s[d + 3]);
        }
        bins.voxels[b] = box;
    });
    return bins;
}

/// Every leaf some bin's kernels reach, in key order.
std::vector<std::uint64_t> reached_leaves(const Bins& bins) {
    std::vector<std::uint64_t> leaves;
    for (const std::array<int, 6>& box : bins.voxels)
        for (int z = floor_div(box[2], k_leaf); z <= floor_div(box[5], k_leaf); ++z)
            for (int y = floor_div(box[1], k_leaf); y <= floor_div(box[4], k_leaf); ++y)
                for (int x = floor_div(box[0], k_leaf); x <= floor_div(box[3], k_leaf); ++x)
                    leaves.push_back(LeafKey::pack({x, y, z}));
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    return leaves;
}

/// The colour field at the voxels of one leaf, summed over the bins within `reach` leaves in a
/// fixed order (bins by key, splats by index), so each voxel's sum has the same bits on any
/// thread count.
void fill_leaf(const std::array<int, 3>& leaf, int reach, const Bins& bins,
               const std::vector<Splat>& splats, Real voxel, std::array<double, Leaf::SIZE>& c) {
    c.fill(0);
    const std::array<int, 3> lo{leaf[0] * k_leaf, leaf[1] * k_leaf, leaf[2] * k_leaf};
    for (int dz = -reach; dz <= reach; ++dz)
        for (int dy = -reach; dy <= reach; ++dy)
            for (int dx = -reach; dx <= reach; ++dx) {
                const Index b =
                    bins.find(LeafKey::pack({leaf[0] + dx, leaf[1] + dy, leaf[2] + dz}));
                if (b < 0) continue;
                for (Index k = bins.start[b]; k < bins.start[b + 1]; ++k) {
                    const Splat& s = splats[bins.order[k]];
                    std::array<int, 6> box = voxel_box(s, voxel);
                    bool empty = false;
                    for (int d = 0; d < 3; ++d) {
                        box[d] = std::max(box[d], lo[d]);
                        box[d + 3] = std::min(box[d + 3], lo[d] + k_leaf - 1);
                        empty |= box[d] > box[d + 3];
                    }
                    if (empty) continue;
                    // G (p - centre) along a row of voxels in z: a start and a fixed step.
                    const Vec3 step = voxel * s.G.col(2);
                    for (int i = box[0]; i <= box[3]; ++i)
                        for (int j = box[1]; j <= box[4]; ++j) {
                            Vec3 u = s.G * (voxel * Vec3(i, j, box[2]) - s.centre);
                            // OpenVDB's leaf offset: z fastest, then y, then x.
                            double* row = c.data() + ((i - lo[0]) << 6 | (j - lo[1]) << 3);
                            for (int l = box[2]; l <= box[5]; ++l, u += step) {
                                const Real q2 = u.squaredNorm();
                                if (q2 < 1) row[l - lo[2]] += s.weight * unit_cubic(std::sqrt(q2));
                            }
                        }
                }
            }
}

openvdb::FloatGrid::Ptr level_set_grid(const std::vector<Splat>& splats, Real voxel, Real iso) {
    const Bins bins = bin_splats(splats, voxel);
    const std::vector<std::uint64_t> keys = reached_leaves(bins);
    Real reach = 0;
    for (const Splat& s : splats) reach = std::max(reach, s.reach.maxCoeff());
    // A bin's centres lie within half a voxel of its leaf, so its kernels reach this many leaves.
    const int bin_reach = int(std::ceil((reach / voxel + 0.5) / k_leaf));

    std::vector<std::unique_ptr<Leaf>> leaves(keys.size());
    parallel_for(Index(keys.size()), [&](Index k) {
        const std::array<int, 3> leaf = LeafKey::unpack(keys[k]);
        std::array<double, Leaf::SIZE> c;
        fill_leaf(leaf, bin_reach, bins, splats, voxel, c);
        if (*std::max_element(c.begin(), c.end()) <= 0) return;
        auto node = std::make_unique<Leaf>(
            openvdb::Coord(leaf[0] * k_leaf, leaf[1] * k_leaf, leaf[2] * k_leaf), float(iso), true);
        for (openvdb::Index v = 0; v < Leaf::SIZE; ++v) node->setValueOnly(v, float(iso - c[v]));
        leaves[k] = std::move(node);
    });
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(float(iso));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    grid->setName("fluid_level_set");
    for (std::unique_ptr<Leaf>& leaf : leaves)
        if (leaf) grid->tree().addLeaf(leaf.release());
    return grid;
}

}  // namespace

SurfaceMesh colour_field_surface(const std::vector<Vec3>& x, const std::vector<Real>& volume,
                                 Real h, const FluidSurfaceOptions& options,
                                 std::string* level_set) {
    static std::once_flag initialised;
    std::call_once(initialised, [] { openvdb::initialize(); });
    SurfaceMesh mesh;
    if (x.empty()) return mesh;
    const std::vector<Splat> splats = make_splats(x, volume, h, options.anisotropic);
    const openvdb::FloatGrid::Ptr grid = level_set_grid(splats, options.voxel, options.iso);
    if (level_set) {
        std::ostringstream bytes;
        openvdb::io::Stream(bytes).write({grid});
        *level_set = std::move(bytes).str();
    }

    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0);

    std::vector<Vec3>& v = mesh.vertices.x;
    v.resize(points.size());
    for (size_t i = 0; i < points.size(); ++i)
        v[i] = Vec3(points[i][0], points[i][1], points[i][2]);
    // VolumeToMesh winds its polygons counter-clockwise seen from outside (phi > 0).
    for (const openvdb::Vec3I& t : triangles)
        mesh.triangles.push_back({Index(t[0]), Index(t[1]), Index(t[2])});
    for (const openvdb::Vec4I& q : quads) {
        const Index a = q[0], b = q[1], c = q[2], d = q[3];
        // The shorter diagonal makes the better pair of triangles.
        if ((v[a] - v[c]).squaredNorm() <= (v[b] - v[d]).squaredNorm())
            mesh.triangles.push_back({a, b, c}), mesh.triangles.push_back({a, c, d});
        else
            mesh.triangles.push_back({a, b, d}), mesh.triangles.push_back({b, c, d});
    }
    mesh.vertices.add_vector("normal", vertex_normals(v, mesh.triangles));
    return mesh;
}

std::vector<std::vector<Real>> shepard_interpolate(const std::vector<Vec3>& at,
                                                   const std::vector<Vec3>& x,
                                                   const std::vector<Real>& volume, Real support,
                                                   const std::vector<std::vector<Real>>& columns) {
    std::vector<std::vector<Real>> out(columns.size(), std::vector<Real>(at.size(), 0));
    if (at.empty() || x.empty()) return out;
    Aabb box;
    for (const Vec3& p : x) box.extend(p);
    for (const Vec3& p : at) box.extend(p);
    const UniformGrid grid(box.padded(support), support);
    CellRanges cells;
    sort_into_cells(grid, x, cells);
    const CubicKernel kernel(support);
    parallel_for(Index(at.size()), [&](Index i) {
        Real weight = 0;
        std::vector<Real> sum(columns.size(), 0);
        for_each_within(grid, cells, at[i], [&](Index j, const Vec3& xj) {
            const Real w = volume[j] * kernel.w((at[i] - xj).norm());
            weight += w;
            for (size_t k = 0; k < columns.size(); ++k) sum[k] += w * columns[k][j];
        });
        if (weight > 0)
            for (size_t k = 0; k < columns.size(); ++k) out[k][i] = sum[k] / weight;
    });
    return out;
}

}  // namespace karst
