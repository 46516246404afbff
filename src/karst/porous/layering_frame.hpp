#pragma once
// Weighted PCA of a particle's neighbourhood (docs/method.md §6.2, Yu & Turk 2013, M28): the local
// frame of complex geometry. karst uses it for the layering frame ("axes from geometry"; the
// permeability ratios come from the scene through K0, M12, never from sampling noise) and for the
// anisotropic kernels of the fluid surface (§7).
#include "karst/core/types.hpp"

#include <vector>

namespace karst {

struct PcaFrame {
    Mat3 axes = Mat3::Identity();  ///< columns: directions of largest, middle and least spread
    Vec3 spread = Vec3::Ones();  ///< sigma_1 >= sigma_2 >= sigma_3 of the weighted covariance, m^2
    Index neighbours = 0;        ///< particles within r_i = 2 h, itself included
    Vec3 mean = Vec3::Zero();    ///< x^w, the weighted mean of the neighbours, m
    /// Enough neighbours (N > N_eps = 25) for the frame to mean anything.
    bool reliable() const { return neighbours > 25; }
    /// The layering normal of a sheet-like neighbourhood: the direction of least spread.
    Vec3 normal() const { return axes.col(2); }
};

/// Frames of every particle: weights w = 1 - (r / 2h)^3 for r < 2h (§6.2 steps 1-3).
std::vector<PcaFrame> pca_frames(const std::vector<Vec3>& x, Real h);

/// M28's kernel tensor from a frame: G = (1/h) R diag(k_s sigma_1, k_s s_2, k_s s_3)^-1 R^T with
/// s_k = max(sigma_k, sigma_1 / 4) and k_s = (sigma_1 s_2 s_3)^(-1/3) (so det G = h^-3), or
/// G = I / (k_n h), k_n = 0.5, with too few neighbours.
Mat3 pca_kernel_tensor(const PcaFrame& frame, Real h);

}  // namespace karst
