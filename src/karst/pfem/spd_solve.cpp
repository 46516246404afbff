#include "karst/core/check.hpp"
#include "karst/pfem/sparse_linear.hpp"

#include <Eigen/CholmodSupport>

namespace karst {

struct SpdSolve::Direct {
    Eigen::CholmodSupernodalLLT<SparseMatrix> llt;
    bool analysed = false;
};

SpdSolve::SpdSolve() = default;
SpdSolve::~SpdSolve() = default;
SpdSolve::SpdSolve(SpdSolve&&) noexcept = default;
SpdSolve& SpdSolve::operator=(SpdSolve&&) noexcept = default;

void SpdSolve::compute(const SparseMatrix& A, bool iterative, const AmgOptions& amg_options) {
    m_iterative = iterative;
    if (iterative) {
        m_amg.reset();  // free the old hierarchy before building the next
        m_amg = std::make_unique<AmgSolver>(A, amg_options);
        return;
    }
    if (!m_direct) m_direct = std::make_unique<Direct>();
    if (!m_direct->analysed) m_direct->llt.analyzePattern(A), m_direct->analysed = true;
    m_direct->llt.factorize(A);
    KARST_CHECK(m_direct->llt.info() == Eigen::Success);
}

Vector SpdSolve::solve(const Vector& b, const Vector& guess) {
    if (!m_iterative) return m_direct->llt.solve(b);
    Vector x = guess;
    iterations += m_amg->solve(b, x);
    return x;
}

}  // namespace karst
