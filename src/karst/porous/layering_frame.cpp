#include "karst/porous/layering_frame.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <Eigen/Eigenvalues>

namespace karst {

std::vector<PcaFrame> pca_frames(const std::vector<Vec3>& x, Real h) {
    const Real radius = 2 * h;
    Aabb box;
    for (const Vec3& p : x) box.extend(p);
    const UniformGrid grid(box.padded(radius), radius / 2);
    CellRanges cells;
    sort_into_cells(grid, x, cells);

    // About 270 neighbours within 2 h = 4 dx: visited once, in place (itself included), not
    // listed. The sums are of offsets d = x_j - x_i, so the covariance about the weighted mean,
    // S2/W - (S1/W)(S1/W)^T, subtracts numbers of the neighbourhood's size, not the domain's.
    std::vector<PcaFrame> frames(x.size());
    const Real inv_radius3 = 1 / (radius * radius * radius);
    parallel_for(Index(x.size()), [&](Index i) {
        Real weight = 0;
        Vec3 first = Vec3::Zero();
        Mat3 second = Mat3::Zero();
        Index count = 0;
        for_each_within(grid, cells, x[i], radius, [&](Index, const Vec3& xj) {
            const Vec3 d = xj - x[i];
            const Real r2 = d.squaredNorm(), w = 1 - r2 * std::sqrt(r2) * inv_radius3;
            weight += w, first += w * d, second += w * d * d.transpose(), ++count;
        });
        const Vec3 offset = first / weight;
        const Mat3 covariance = second / weight - offset * offset.transpose();
        const Vec3 mean = x[i] + offset;
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(covariance);  // ascending
        PcaFrame& f = frames[i];
        f.neighbours = count;
        f.mean = mean;
        f.spread = eigen.eigenvalues().reverse();
        f.axes = eigen.eigenvectors().rowwise().reverse();
    });
    return frames;
}

Mat3 pca_kernel_tensor(const PcaFrame& frame, Real h) {
    if (!frame.reliable()) return Mat3::Identity() / (0.5 * h);
    const Real s1 = frame.spread[0], s2 = std::max(frame.spread[1], s1 / 4),
               s3 = std::max(frame.spread[2], s1 / 4);
    const Real ks = std::cbrt(1 / (s1 * s2 * s3));
    const Vec3 inverse = Vec3(ks * s1, ks * s2, ks * s3).cwiseInverse();
    return frame.axes * inverse.asDiagonal() * frame.axes.transpose() / h;
}

}  // namespace karst
