#pragma once
// Anderson acceleration of the fixed-stress pressure iterates (beyond M22).
#include <Eigen/Core>
#include <Eigen/QR>

#include <vector>

namespace karst {

/// Anderson acceleration of a fixed-point iteration x <- G(x) (Walker & Ni 2011, type II): the
/// next iterate mixes the last `depth` results so as to minimise the linearised residual
/// G(x) - x.
class AndersonMixing {
public:
    explicit AndersonMixing(int depth) : m_depth(depth) {}
    /// x: the current iterate; g = G(x). Returns the next iterate.
    Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& g) {
        Eigen::VectorXd f = g - x;
        if (m_last_f.size() > 0) {
            m_df.push_back(f - m_last_f), m_dg.push_back(g - m_last_g);
            if (int(m_df.size()) > m_depth) m_df.erase(m_df.begin()), m_dg.erase(m_dg.begin());
        }
        m_last_f = f, m_last_g = g;
        if (m_df.empty()) return g;
        Eigen::MatrixXd DF(f.size(), Eigen::Index(m_df.size()));
        for (size_t j = 0; j < m_df.size(); ++j) DF.col(Eigen::Index(j)) = m_df[j];
        const Eigen::VectorXd gamma = DF.colPivHouseholderQr().solve(f);
        Eigen::VectorXd out = g;
        for (size_t j = 0; j < m_dg.size(); ++j) out -= gamma[Eigen::Index(j)] * m_dg[j];
        return out;
    }

private:
    int m_depth;
    std::vector<Eigen::VectorXd> m_df, m_dg;
    Eigen::VectorXd m_last_f, m_last_g;
};

}  // namespace karst
