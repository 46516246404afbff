// Assembly of the Biot problem's matrices (docs/method.md §5.3): P1 tets or M21 polyhedra for the
// elasticity K, coupling Q, consistent mass, lumped volume and body force; the Darcy matrix H
// and gravity flux b; the free and prescribed unknowns. The weak form is in biot.cpp.
#include "karst/core/parallel.hpp"
#include "karst/pfem/biot_impl.hpp"

namespace karst {

namespace {

/// Isotropic elasticity in Voigt order (xx, yy, zz, yz, xz, xy), engineering shear strains.
Eigen::Matrix<Real, 6, 6> elasticity_matrix(const BiotMaterial& m) {
    const Real lambda = m.lame_lambda(), mu = m.shear_modulus();
    Eigen::Matrix<Real, 6, 6> D = Eigen::Matrix<Real, 6, 6>::Zero();
    D.topLeftCorner<3, 3>().setConstant(lambda);
    for (int i = 0; i < 3; ++i) D(i, i) = lambda + 2 * mu, D(i + 3, i + 3) = mu;
    return D;
}

/// Writes node a's three columns of the strain-displacement matrix B_u (Voigt order, engineering
/// shear) for the shape-function gradient g.
template <class Matrix>
void set_strain_displacement_columns(Matrix& B, int a, const Vec3& g) {
    const int c = 3 * a;
    B(0, c) = g[0], B(1, c + 1) = g[1], B(2, c + 2) = g[2];
    B(3, c + 1) = g[2], B(3, c + 2) = g[1];
    B(4, c) = g[2], B(4, c + 2) = g[0];
    B(5, c) = g[1], B(5, c + 1) = g[0];
}

}  // namespace

void BiotSolver::Impl::assemble_p1_mechanics() {
    const BiotMaterial& m = problem.material;
    const Real lambda = m.lame_lambda(), mu = m.shear_modulus();
    // Tets around each node; each node's sorted neighbour nodes (itself included).
    std::vector<Index> tet_start(n + 1, 0), tet_list(4 * mesh.tet_count());
    for (const Tet& t : mesh.tets)
        for (Index a : t) ++tet_start[a + 1];
    for (Index a = 0; a < n; ++a) tet_start[a + 1] += tet_start[a];
    {
        std::vector<Index> fill(tet_start.begin(), tet_start.end() - 1);
        for (Index e = 0; e < mesh.tet_count(); ++e)
            for (Index a : mesh.tets[e]) tet_list[fill[a]++] = e;
    }
    const std::vector<std::vector<Index>> neighbours = node_neighbours(mesh);
    auto free_u = [&](Index a, int c) { return u_dofs.free_index[3 * a + c]; };

    // Column pointers of K_ff (free dofs in order), Q (n columns of 3 rows per neighbour) and M.
    const int nf = u_dofs.free_count;
    std::vector<int> k_outer(nf + 1, 0), q_outer(n + 1, 0), m_outer(n + 1, 0);
    for (Index b = 0; b < n; ++b) {
        int free_rows = 0;
        for (Index a : neighbours[b])
            for (int c = 0; c < 3; ++c) free_rows += free_u(a, c) >= 0;
        for (int d = 0; d < 3; ++d)
            if (const int col = free_u(b, d); col >= 0) k_outer[col + 1] = free_rows;
        q_outer[b + 1] = q_outer[b] + 3 * int(neighbours[b].size());
        m_outer[b + 1] = m_outer[b] + int(neighbours[b].size());
    }
    for (int col = 0; col < nf; ++col) k_outer[col + 1] += k_outer[col];
    K_ff.resize(nf, nf), Q.resize(3 * n, n), mass.resize(n, n);
    K_ff.resizeNonZeros(k_outer[nf]), Q.resizeNonZeros(q_outer[n]), mass.resizeNonZeros(m_outer[n]);
    std::copy(k_outer.begin(), k_outer.end(), K_ff.outerIndexPtr());
    std::copy(q_outer.begin(), q_outer.end(), Q.outerIndexPtr());
    std::copy(m_outer.begin(), m_outer.end(), mass.outerIndexPtr());

    lumped_volume = Vector::Zero(n);
    f_ext = Vector::Zero(3 * n);
    std::vector<int> prescribed_index(3 * n, -1);
    for (int i = 0, k = 0; i < 3 * n; ++i)
        if (u_dofs.free_index[i] < 0) prescribed_index[i] = k++;
    std::vector<Triplets> lift_entries(n);     // K_fc, per column-owning node b
    std::vector<Triplets> support_entries(n);  // K_cc, likewise
    parallel_for(n, [&](Index b) {
        const auto& nb = neighbours[b];
        std::vector<Mat3> block(nb.size(), Mat3::Zero());
        std::vector<Vec3> coupling(nb.size(), Vec3::Zero());
        std::vector<Real> consistent(nb.size(), 0);
        for (Index k = tet_start[b]; k < tet_start[b + 1]; ++k) {
            const Index e = tet_list[k];
            const P1Tet& p = elements[e];
            const Tet& t = mesh.tets[e];
            const int ib = int(std::find(t.begin(), t.end(), b) - t.begin());
            const Vec3& gb = p.grad[ib];
            for (int ia = 0; ia < 4; ++ia) {
                const size_t pos =
                    size_t(std::lower_bound(nb.begin(), nb.end(), t[ia]) - nb.begin());
                const Vec3& ga = p.grad[ia];
                block[pos] +=
                    p.volume * (lambda * gb * ga.transpose() + mu * ga.dot(gb) * Mat3::Identity() +
                                mu * ga * gb.transpose());
                coupling[pos] += (m.biot_coefficient * p.volume / 4) * ga;  // Q[3a+c, b]
                consistent[pos] += p.volume * (ia == ib ? 2 : 1) / 20;
            }
            lumped_volume[b] += p.volume / 4;
            f_ext.segment<3>(3 * b) += m.bulk_density * problem.gravity * (p.volume / 4);
        }
        // K_ff columns of b (= rows, K is symmetric) and the lift of prescribed neighbours.
        for (int d = 0; d < 3; ++d) {
            const int col = free_u(b, d);
            if (col < 0) {
                for (size_t pos = 0; pos < nb.size(); ++pos)
                    for (int c = 0; c < 3; ++c)
                        if (free_u(nb[pos], c) < 0)
                            support_entries[b].emplace_back(prescribed_index[3 * nb[pos] + c],
                                                            prescribed_index[3 * b + d],
                                                            block[pos](d, c));
                continue;
            }
            int at = k_outer[col];
            for (size_t pos = 0; pos < nb.size(); ++pos)
                for (int c = 0; c < 3; ++c) {
                    const Real value = block[pos](d, c);
                    if (const int row = free_u(nb[pos], c); row >= 0) {
                        K_ff.innerIndexPtr()[at] = row;
                        K_ff.valuePtr()[at++] = nb[pos] == b && c == d && problem.free_body
                                                    ? value * (1 + problem.rigid_mode_spring)
                                                    : value;
                    } else {
                        lift_entries[b].emplace_back(col, prescribed_index[3 * nb[pos] + c], value);
                    }
                }
        }
        int at = q_outer[b];
        for (size_t pos = 0; pos < nb.size(); ++pos)
            for (int c = 0; c < 3; ++c)
                Q.innerIndexPtr()[at] = int(3 * nb[pos] + c), Q.valuePtr()[at++] = coupling[pos][c];
        at = m_outer[b];
        for (size_t pos = 0; pos < nb.size(); ++pos)
            mass.innerIndexPtr()[at] = int(nb[pos]), mass.valuePtr()[at++] = consistent[pos];
    });
    Triplets lift;
    for (const Triplets& t : lift_entries) lift.insert(lift.end(), t.begin(), t.end());
    K_fc.resize(nf, 3 * n - nf);
    K_fc.setFromTriplets(lift.begin(), lift.end());
    Triplets support;
    for (const Triplets& t : support_entries) support.insert(support.end(), t.begin(), t.end());
    K_cc.resize(3 * n - nf, 3 * n - nf);
    K_cc.setFromTriplets(support.begin(), support.end());
    storage = problem.material.storage * lumped_volume;
}

void BiotSolver::Impl::assemble_polyhedral_mechanics() {
    const BiotMaterial& m = problem.material;
    const auto D = elasticity_matrix(m);
    Triplets k_entries, q_entries;
    lumped_volume = Vector::Zero(n);
    f_ext = Vector::Zero(3 * n);
    for (const PolyhedralElement& element : polyhedra) {
        const int size = int(element.nodes.size());
        Eigen::MatrixXd Ke = Eigen::MatrixXd::Zero(3 * size, 3 * size),
                        Qe = Eigen::MatrixXd::Zero(3 * size, size);
        Eigen::Matrix<Real, 6, Eigen::Dynamic> B(6, 3 * size);
        for (const PolyhedralElement::Point& q : element.points) {
            B.setZero();
            for (int a = 0; a < size; ++a) {
                const Vec3& g = q.grad[a];
                set_strain_displacement_columns(B, a, g);
                lumped_volume[element.nodes[a]] += q.weight * q.N[a];
                f_ext.segment<3>(3 * element.nodes[a]) +=
                    m.bulk_density * problem.gravity * (q.weight * q.N[a]);
                for (int b = 0; b < size; ++b)
                    for (int d = 0; d < 3; ++d)
                        Qe(3 * a + d, b) += q.weight * m.biot_coefficient * g[d] * q.N[b];
            }
            Ke += q.weight * B.transpose() * D * B;
        }
        for (int a = 0; a < size; ++a)
            for (int c = 0; c < 3; ++c) {
                const int row = int(3 * element.nodes[a] + c);
                for (int b = 0; b < size; ++b) {
                    for (int d = 0; d < 3; ++d)
                        k_entries.emplace_back(row, int(3 * element.nodes[b] + d),
                                               Ke(3 * a + c, 3 * b + d));
                    q_entries.emplace_back(row, int(element.nodes[b]), Qe(3 * a + c, b));
                }
            }
    }
    K.resize(3 * n, 3 * n);
    K.setFromTriplets(k_entries.begin(), k_entries.end());
    Q.resize(3 * n, n);
    Q.setFromTriplets(q_entries.begin(), q_entries.end());
    mass.resize(n, n);
    for (Index a = 0; a < n; ++a) mass.insert(a, a) = lumped_volume[a];
    if (problem.free_body)
        for (int i = 0; i < 3 * n; ++i) K.coeffRef(i, i) *= 1 + problem.rigid_mode_spring;
    storage = problem.material.storage * lumped_volume;
}

void BiotSolver::Impl::assemble_polyhedral_flow(Triplets& h_entries, const Vec3& rho_g) {
    for (const PolyhedralElement& element : polyhedra)
        for (const PolyhedralElement::Point& q : element.points) {
            const Mat3& mobility = problem.mobility[q.tet];
            for (size_t a = 0; a < element.nodes.size(); ++a) {
                const Vec3 flux_a = mobility * q.grad[a];
                for (size_t b = 0; b < element.nodes.size(); ++b)
                    h_entries.emplace_back(int(element.nodes[a]), int(element.nodes[b]),
                                           q.weight * flux_a.dot(q.grad[b]));
                gravity_flux[element.nodes[a]] += q.weight * flux_a.dot(rho_g);
            }
        }
}

void BiotSolver::Impl::assemble_flow() {
    Triplets h_entries;
    h_entries.reserve(size_t(mesh.tet_count()) * 16);
    gravity_flux = Vector::Zero(n);
    const Vec3 rho_g = problem.material.fluid_density * problem.gravity;
    if (options.polyhedral) assemble_polyhedral_flow(h_entries, rho_g);
    for (Index e = 0; e < mesh.tet_count() && !options.polyhedral; ++e) {
        const P1Tet& p = elements[e];
        const Tet& t = mesh.tets[e];
        const Mat3& mobility = problem.mobility[e];
        for (int a = 0; a < 4; ++a) {
            const Vec3 flux_a = mobility * p.grad[a];  // Lambda is symmetric
            for (int b = 0; b < 4; ++b)
                h_entries.emplace_back(int(t[a]), int(t[b]), p.volume * flux_a.dot(p.grad[b]));
            gravity_flux[t[a]] += p.volume * flux_a.dot(rho_g);
        }
    }
    H.resize(n, n);
    H.setFromTriplets(h_entries.begin(), h_entries.end());
    if (!p_dofs.free_index.empty()) std::tie(H_ff, H_fc) = p_dofs.split(H);
    mobility_changed = true;
}

void BiotSolver::Impl::split_dofs() {
    std::vector<char> u_fixed(3 * n, 0), p_fixed(n, 0);
    u_prescribed = Vector::Zero(3 * n);
    p_prescribed = Vector::Zero(n);
    for (Index a = 0; a < Index(problem.fixed.size()); ++a)
        for (int c = 0; c < 3; ++c)
            if (problem.fixed[a] & (1 << c)) {
                u_fixed[3 * a + c] = 1;
                if (!problem.prescribed_u.empty())
                    u_prescribed[3 * a + c] = problem.prescribed_u[a][c];
            }
    for (Index a = 0; a < Index(problem.drained.size()); ++a)
        if (problem.drained[a]) {
            p_fixed[a] = 1;
            if (!problem.drained_pressure.empty()) p_prescribed[a] = problem.drained_pressure[a];
        }
    // Nodes outside every assembled tet have no equations: hold them where they are.
    std::vector<char> attached(n, 0);
    for (const Tet& t : mesh.tets)
        for (Index a : t) attached[a] = 1;
    for (Index a = 0; a < n; ++a)
        if (!attached[a]) u_fixed[3 * a] = u_fixed[3 * a + 1] = u_fixed[3 * a + 2] = p_fixed[a] = 1;
    u_dofs = DofSplit(u_fixed);
    p_dofs = DofSplit(p_fixed);
}

}  // namespace karst
