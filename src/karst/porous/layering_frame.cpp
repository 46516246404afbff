#include "karst/porous/layering_frame.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <Eigen/Eigenvalues>

namespace karst {

std::vector<PcaFrame> pca_frames(const std::vector<Vec3>& x, Real h) {
    const Real radius = 2 * h;
    Aabb box;
    for (const Vec3& p : x) box.extend(p);
    const UniformGrid grid(box.padded(radius), radius);
    CellRanges cells;
    sort_into_cells(grid, x, cells);

    // About 270 neighbours within 2 h = 4 dx: visited in place (itself included), not listed.
    std::vector<PcaFrame> frames(x.size());
    parallel_for(Index(x.size()), [&](Index i) {
        Real weight = 0;
        Vec3 mean = Vec3::Zero();
        Index count = 0;
        for_each_within(grid, cells, x[i], [&](Index, const Vec3& xj) {
            const Real r = (xj - x[i]).norm() / radius, w = 1 - r * r * r;
            weight += w, mean += w * xj, ++count;
        });
        mean /= weight;
        Mat3 covariance = Mat3::Zero();
        for_each_within(grid, cells, x[i], [&](Index, const Vec3& xj) {
            const Real r = (xj - x[i]).norm() / radius, w = 1 - r * r * r;
            const Vec3 d = xj - mean;
            covariance += w * d * d.transpose();
        });
        covariance /= weight;
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
