#include "karst/pfem/merge_stage.hpp"

#include "karst/core/disjoint_sets.hpp"
#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/tet_mesh.hpp"
#include "karst/rigid/fragment_motion.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace karst {

namespace {

/// What the particles of two fragments within h of each other say about their contact.
struct Contact {
    std::set<Index> particles;  ///< of both fragments
    Real closing_speed = 0;     ///< largest |(v_i - v_j) . r_hat| over the pairs, m/s
    bool across_crack = false;  ///< some pair is the two halves of one split particle
};

/// Fragments touching each other, by fragment pair (a < b), from the step's porous neighbour
/// lists (pairs within h at the step's start: a slow contact moves a small part of h in a step),
/// or from a fresh search when dissolution removed particles since they were made.
std::map<std::pair<Index, Index>, Contact> contacts(const Model& model, const State& state) {
    const PorousParticles& p = state.porous.particles;
    NeighbourLists fresh;
    const NeighbourLists* lists = &state.porous_scratch.porous_porous;
    if (Index(lists->count.size()) != p.size()) {
        CellRanges cells;
        sort_into_cells(model.grid, p.x, cells);
        find_neighbours(model.grid, p.x, cells, true, fresh);
        lists = &fresh;
    }
    const NeighbourLists& near = *lists;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    std::map<std::pair<Index, Index>, Contact> found;
    for (Index i = 0; i < p.size(); ++i)
        near.for_each(i, [&](Index j) {
            const Index fi = p.fragment[i], fj = p.fragment[j];
            if (j <= i || fi == fj || (fragments[fi].anchored && fragments[fj].anchored)) return;
            Contact& c = found[{std::min(fi, fj), std::max(fi, fj)}];
            c.particles.insert(i), c.particles.insert(j);
            const Vec3 r = p.x[i] - p.x[j];
            if (r.norm() > 0)
                c.closing_speed =
                    std::max(c.closing_speed, std::abs((p.v[i] - p.v[j]).dot(r.normalized())));
            c.across_crack = c.across_crack || p.origin[i] == p.origin[j];
        });
    return found;
}

/// The merge test of §5.6: saturated contact, slow, and held together by the weighted alpha
/// shape of the contact particles (at least N_m of its tets have nodes in both fragments).
bool should_merge(const Model& model, const State& state, Index a, const Contact& c) {
    const FractureSettings& settings = model.scene.fracture;
    if (c.across_crack || c.closing_speed >= settings.merge_speed) return false;
    const PorousParticles& p = state.porous.particles;
    Real saturation = 0;
    std::vector<Vec3> x;
    std::vector<char> in_a;
    for (Index i : c.particles) {
        const PoreWaterLaw& law = model.pore_laws[p.material_of(i)];
        saturation += p.porosity[i] > k_min_porosity
                          ? law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i])
                          : 0;
        x.push_back(p.x[i]), in_a.push_back(p.fragment[i] == a);
    }
    if (saturation / Real(c.particles.size()) < settings.merge_saturation || x.size() < 4)
        return false;
    MeshOptions options;
    options.alpha = model.scene.poroelastic.alpha, options.weighted = true;
    const std::vector<Real> size(x.size(), model.dx);
    const std::vector<Real> weights(x.size(), alpha_shape_weight(model.dx));
    const TetMesh mesh = build_tet_mesh(x, size, options, weights);
    Index spanning = 0;
    for (const Tet& t : mesh.tets) {
        const int from_a = in_a[t[0]] + in_a[t[1]] + in_a[t[2]] + in_a[t[3]];
        spanning += from_a > 0 && from_a < 4;
    }
    return spanning >= k_merge_spanning_tets;
}

/// Members of fragment `from` join the anchored fragment `into` and its structure (rest state
/// = where they are, no displacement); the structure is remeshed at its next call.
void join_anchored(State& state, Index from, Index into) {
    PorousParticles& p = state.porous.particles;
    StructureState& st = state.structures;
    const Fragment& anchor = state.porous.fragments[into];
    const Mat3 R = anchor.rotation_matrix();
    st.grow_ids(size_t(state.next_id));
    for (Index k = 0; k < p.size(); ++k) {
        if (p.fragment[k] != from) continue;
        p.fragment[k] = into;
        p.rest[k] = R.transpose() * (p.x[k] - anchor.centre);
        p.body_permeability[k] = R.transpose() * p.permeability[k] * R;
        const Index id = p.id[k];
        st.rest_x[id] = p.x[k], st.u[id] = Vec3::Zero(), st.impulse[id] = Vec3::Zero();
        st.weight_u[id] = Vec3::Zero();  // its weight is a new load on the structure
        st.rest_tensor[id] = p.body_permeability[k], st.rest_volume[id] = p.volume[k];
        st.paired_scale[id] = 1, st.paired_volume[id] = p.volume[k];
    }
    for (Structure& s : st.structures)
        if (s.fragment == into) s.grown = true;
}

}  // namespace

bool merge_fragments(const Model& model, State& state) {
    if (!model.scene.fracture.merge) return false;
    std::vector<Fragment>& fragments = state.porous.fragments;
    Index live = 0, free = 0;
    for (const Fragment& f : fragments) live += f.mass > 0, free += f.mass > 0 && !f.anchored;
    if (live < 2 || free == 0) return false;

    DisjointSets groups(Index(fragments.size()));
    bool any = false;
    for (const auto& [pair, contact] : contacts(model, state))
        if (should_merge(model, state, pair.first, contact))
            groups.join(pair.first, pair.second), any = true;
    if (!any) return false;

    // Each group becomes its anchored fragment (at most one: two anchored never join) or its
    // smallest index; the others are left empty.
    PorousParticles& p = state.porous.particles;
    std::vector<Index> target(fragments.size());
    for (Index f = 0; f < Index(fragments.size()); ++f) target[f] = groups.find(f);
    for (Index f = 0; f < Index(fragments.size()); ++f)
        if (fragments[f].anchored && fragments[f].mass > 0) {
            const Index root = groups.find(f);
            if (fragments[target[root]].anchored && target[root] != f) continue;  // two anchors
            target[root] = f;
        }
    std::map<Index, std::vector<Index>> free_members;  // target -> members, of free groups
    for (Index f = 0; f < Index(fragments.size()); ++f) {
        const Index into = target[groups.find(f)];
        if (into == f || fragments[f].mass == 0) continue;
        if (fragments[f].anchored) continue;  // a second anchor keeps its own structure
        ++state.structures.fracture.merges;
        fragments[f] = Fragment{};  // empty: mass 0
        if (fragments[into].anchored) {
            join_anchored(state, f, into);
            continue;
        }
        for (Index k = 0; k < p.size(); ++k)
            if (p.fragment[k] == f) p.fragment[k] = into;
        free_members[into];
    }
    // A free group is one rigid body in its current pose with its members' momentum.
    for (auto& [into, members] : free_members) {
        for (Index k = 0; k < p.size(); ++k)
            if (p.fragment[k] == into) members.push_back(k);
        fragments[into] = free_fragment(p, members, model.dx);
    }
    return true;
}

}  // namespace karst
