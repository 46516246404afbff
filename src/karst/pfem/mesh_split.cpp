#include "karst/pfem/mesh_split.hpp"

#include "karst/core/disjoint_sets.hpp"
#include "karst/pfem/face_links.hpp"

#include <algorithm>
#include <numeric>

namespace karst {

namespace {

/// Renumbers ids 0, 1, ... in order of first appearance.
void compact_ids(std::vector<Index>& ids) {
    std::vector<Index> number;
    Index next = 0;
    for (Index& id : ids) {
        if (id >= Index(number.size())) number.resize(id + 1, -1);
        if (number[id] < 0) number[id] = next++;
        id = number[id];
    }
}

/// Recomputes the EDT groups (M20) so that no group spans a broken link.
std::vector<Index> regroup_polyhedra(const TetMesh& mesh, std::span<const ElementLink> unbroken) {
    DisjointSets sets(mesh.tet_count());
    for (const ElementLink& l : unbroken)
        if (mesh.tet_polyhedron[l.a] == mesh.tet_polyhedron[l.b]) sets.join(l.a, l.b);
    std::vector<Index> group(mesh.tet_count());
    for (Index e = 0; e < mesh.tet_count(); ++e) group[e] = sets.find(e);
    compact_ids(group);
    return group;
}

}  // namespace

std::vector<Triangle> boundary_faces(std::span<const Tet> tets) {
    // Outward faces of a positively oriented tet (a, b, c, d), opposite a, b, c, d.
    constexpr int k_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    struct Face {
        std::array<Index, 3> key;
        Triangle oriented;
    };
    std::vector<Face> faces;
    faces.reserve(4 * tets.size());
    for (const Tet& t : tets)
        for (const auto& f : k_face) {
            Face face{{t[f[0]], t[f[1]], t[f[2]]}, {t[f[0]], t[f[1]], t[f[2]]}};
            std::sort(face.key.begin(), face.key.end());
            faces.push_back(face);
        }
    std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
        return a.key != b.key ? a.key < b.key : a.oriented < b.oriented;
    });
    std::vector<Triangle> boundary;
    for (size_t k = 0; k < faces.size();) {
        size_t end = k + 1;
        while (end < faces.size() && faces[end].key == faces[k].key) ++end;
        if (end == k + 1) boundary.push_back(faces[k].oriented);
        k = end;
    }
    return boundary;
}

MeshSplit split_mesh(const TetMesh& mesh, std::span<const ElementLink> links,
                     std::span<const char> broken, Real offset) {
    const Index n = mesh.node_count(), ne = mesh.tet_count();
    MeshSplit out;
    for (size_t k = 0; k < links.size(); ++k)
        if (!broken[k]) out.links.push_back(links[k]);

    // The tets around every node (CSR), and the groups among them over unbroken links.
    std::vector<Index> start(n + 1, 0);
    for (const Tet& t : mesh.tets)
        for (Index a : t) ++start[a + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<Index> around(start[n]);
    {
        std::vector<Index> fill(start.begin(), start.end() - 1);
        for (Index e = 0; e < ne; ++e)
            for (Index a : mesh.tets[e]) around[fill[a]++] = e;
    }
    // Local union-find: slot of tet e around node a; the sets live on the CSR slots.
    DisjointSets slots(start[n]);
    auto slot_of = [&](Index a, Index e) {
        return Index(std::lower_bound(around.begin() + start[a], around.begin() + start[a + 1], e) -
                     around.begin());
    };
    for (const ElementLink& l : out.links)
        for (Index a : shared_nodes(mesh, l)) slots.join(slot_of(a, l.a), slot_of(a, l.b));

    // The cut faces at each node, area-weighted, pointing into the tet on each side: a copy moves
    // away from the faces that cut its group off, along the crack (a move towards its group's
    // centroid tilts into the body at a surface node and brought copies across a crack closer).
    std::vector<Vec3> away_from_cut(start[n], Vec3::Zero());
    for (size_t k = 0; k < links.size(); ++k) {
        if (!broken[k]) continue;
        const ElementLink& l = links[k];
        const SharedNodes face = shared_nodes(mesh, l);
        if (face.count != 3) continue;
        const std::array<Index, 3>& f = face.node;
        Vec3 normal =
            0.5 * (mesh.nodes[f[1]] - mesh.nodes[f[0]]).cross(mesh.nodes[f[2]] - mesh.nodes[f[0]]);
        if (normal.dot(mesh.tet_centroid(l.b) - mesh.tet_centroid(l.a)) < 0) normal = -normal;
        for (Index a : face) {
            away_from_cut[slot_of(a, l.a)] -= normal;
            away_from_cut[slot_of(a, l.b)] += normal;
        }
    }

    out.mesh = mesh;
    out.source.resize(n);
    std::iota(out.source.begin(), out.source.end(), 0);
    out.share.assign(n, 1);
    std::vector<Vec3> moves;
    for (Index a = 0; a < n; ++a) {
        // Groups in order of their lowest tet: the first keeps the node's index.
        std::vector<Index> roots;
        for (Index s = start[a]; s < start[a + 1]; ++s)
            if (slots.find(s) == s) roots.push_back(s);
        if (roots.size() < 2) continue;
        ++out.split_nodes;
        std::vector<Real> volume(roots.size(), 0);
        std::vector<Vec3> side(roots.size(), Vec3::Zero()), cut(roots.size(), Vec3::Zero());
        std::vector<Index> copy(roots.size());
        for (size_t g = 0; g < roots.size(); ++g) {
            copy[g] = g == 0 ? a : Index(out.source.size());
            if (g > 0) {
                out.source.push_back(a), out.share.push_back(1);
                out.mesh.nodes.push_back(mesh.nodes[a]);
            }
        }
        for (Index s = start[a]; s < start[a + 1]; ++s) {
            const size_t g = std::find(roots.begin(), roots.end(), slots.find(s)) - roots.begin();
            const Index e = around[s];
            const Real v = mesh.tet_volume(e) / 4;
            volume[g] += v;
            cut[g] += away_from_cut[s];
            side[g] += v * (mesh.tet_centroid(e) - mesh.nodes[a]);
            for (Index& node : out.mesh.tets[e])
                if (node == a) node = copy[g];
        }
        // A group of interior slivers alone (tets of next to no volume) still gets a share of
        // at least 1e-3, so that no particle is left with no volume.
        const Real largest = *std::max_element(volume.begin(), volume.end());
        for (Real& v : volume) v = std::max(v, 1e-3 * largest);
        const Real total = std::accumulate(volume.begin(), volume.end(), Real(0));
        Vec3 mean = Vec3::Zero();
        moves.assign(roots.size(), Vec3::Zero());
        for (size_t g = 0; g < roots.size(); ++g) {
            out.share[copy[g]] = volume[g] / total;
            const Vec3& towards = cut[g].norm() > 0 ? cut[g] : side[g];
            if (towards.norm() > 0) moves[g] = offset * towards.normalized();
            mean += out.share[copy[g]] * moves[g];
        }
        // Shorter moves where the full ones would flatten a tet around the node to under half
        // its volume (a thin tet can turn inside out by a twentieth of a spacing); the same
        // factor for every copy keeps the share-weighted sum zero.
        const Vec3 base = mesh.nodes[a];
        for (Real f = 1;; f *= 0.5) {
            if (f < 1.0 / 64) f = 0;
            for (size_t g = 0; g < roots.size(); ++g)
                out.mesh.nodes[copy[g]] = base + f * (moves[g] - mean);
            bool flattened = false;
            for (Index k = start[a]; k < start[a + 1] && !flattened; ++k) {
                const Tet& t = out.mesh.tets[around[k]];
                const Real v = signed_volume(out.mesh.nodes[t[0]], out.mesh.nodes[t[1]],
                                             out.mesh.nodes[t[2]], out.mesh.nodes[t[3]]);
                flattened = v < 0.5 * mesh.tet_volume(around[k]);
            }
            if (!flattened || f == 0) break;
        }
    }

    out.mesh.boundary = boundary_faces(out.mesh.tets);
    if (!out.mesh.tet_polyhedron.empty())
        out.mesh.tet_polyhedron = regroup_polyhedra(mesh, out.links);
    out.component = tet_components(ne, out.links, out.components);
    return out;
}

std::vector<Index> tet_components(Index tet_count, std::span<const ElementLink> links,
                                  Index& count) {
    DisjointSets parts(tet_count);
    for (const ElementLink& l : links) parts.join(l.a, l.b);
    std::vector<Index> component(tet_count), number(tet_count, -1);
    count = 0;
    for (Index e = 0; e < tet_count; ++e) {
        const Index root = parts.find(e);
        if (number[root] < 0) number[root] = count++;
        component[e] = number[root];
    }
    return component;
}

Index cut_sliver_bridges(const TetMesh& mesh, std::span<const ElementLink> links,
                         std::vector<char>& cut, Real min_volume) {
    const Index ne = mesh.tet_count();
    std::vector<char> sliver(ne);
    for (Index e = 0; e < ne; ++e) sliver[e] = mesh.tet_volume(e) < min_volume;
    DisjointSets solid(ne);
    for (size_t k = 0; k < links.size(); ++k)
        if (!cut[k] && !sliver[links[k].a] && !sliver[links[k].b])
            solid.join(links[k].a, links[k].b);
    // Each sliver joins the piece of its first uncut solid neighbour (links are sorted).
    std::vector<Index> piece(ne, -1);
    for (size_t k = 0; k < links.size(); ++k) {
        if (cut[k]) continue;
        const auto [a, b] = links[k];
        if (sliver[a] && !sliver[b] && piece[a] < 0) piece[a] = solid.find(b);
        if (sliver[b] && !sliver[a] && piece[b] < 0) piece[b] = solid.find(a);
    }
    Index added = 0;
    for (size_t k = 0; k < links.size(); ++k) {
        if (cut[k]) continue;
        const auto [a, b] = links[k];
        const Index pa = sliver[a] ? piece[a] : solid.find(a);
        const Index pb = sliver[b] ? piece[b] : solid.find(b);
        if (pa >= 0 && pb >= 0 && pa != pb) cut[k] = 1, ++added;
    }
    return added;
}

Index spare_small_pieces(Index tet_count, std::span<const ElementLink> links,
                         std::vector<char>& cut, Index min_tets,
                         const std::function<bool(std::span<const Index>)>& stays_anchored) {
    Index restored = 0;
    for (bool changed = true; changed;) {
        changed = false;
        DisjointSets sets(tet_count);
        for (size_t k = 0; k < links.size(); ++k)
            if (!cut[k]) sets.join(links[k].a, links[k].b);
        std::vector<std::vector<Index>> pieces(tet_count);
        for (Index e = 0; e < tet_count; ++e) pieces[sets.find(e)].push_back(e);
        std::vector<char> small(tet_count, 0);
        for (Index root = 0; root < tet_count; ++root) {
            const std::vector<Index>& piece = pieces[root];
            small[root] = !piece.empty() && Index(piece.size()) < min_tets &&
                          !(stays_anchored && stays_anchored(piece));
        }
        // A small piece rejoins the one neighbour it shares the most cut faces with (the larger
        // on a tie): restoring its cuts to every side rebuilt the bridges that the other cracks
        // had cut, and a body whose foot a round of cracks crumbled stayed hanging on the crumbs.
        std::vector<std::vector<std::pair<Index, Index>>> shared(tet_count);  // (neighbour, faces)
        for (size_t k = 0; k < links.size(); ++k) {
            if (!cut[k]) continue;
            const Index a = sets.find(links[k].a), b = sets.find(links[k].b);
            if (a == b) continue;
            for (const auto& [from, to] : {std::pair(a, b), std::pair(b, a)}) {
                if (!small[from]) continue;
                auto& list = shared[from];
                auto it = std::find_if(list.begin(), list.end(),
                                       [to](const auto& entry) { return entry.first == to; });
                if (it == list.end())
                    list.push_back({to, 1});
                else
                    ++it->second;
            }
        }
        std::vector<Index> partner(tet_count, -1);
        for (Index root = 0; root < tet_count; ++root) {
            std::pair<Index, Index> best{-1, 0};
            for (const auto& [to, faces] : shared[root])
                if (faces > best.second ||
                    (faces == best.second && pieces[to].size() > pieces[best.first].size()))
                    best = {to, faces};
            partner[root] = best.first;
        }
        for (size_t k = 0; k < links.size(); ++k) {
            if (!cut[k]) continue;
            const Index a = sets.find(links[k].a), b = sets.find(links[k].b);
            if (a != b && (partner[a] == b || partner[b] == a))
                cut[k] = 0, ++restored, changed = true;
        }
    }
    return restored;
}

TetMesh sub_mesh(const TetMesh& mesh, std::span<const char> keep, bool keep_loose_nodes,
                 std::vector<Index>& node_of, std::vector<Index>& tet_of) {
    std::vector<Index> new_index(mesh.node_count(), keep_loose_nodes ? 0 : -1);
    for (const Tet& t : mesh.tets)
        for (Index a : t) new_index[a] = -1;
    for (Index e = 0; e < mesh.tet_count(); ++e)
        if (keep[e])
            for (Index a : mesh.tets[e]) new_index[a] = 0;
    TetMesh out;
    out.quality = mesh.quality;
    node_of.clear(), tet_of.clear();
    for (Index a = 0; a < mesh.node_count(); ++a)
        if (new_index[a] == 0)
            new_index[a] = Index(node_of.size()), node_of.push_back(a),
            out.nodes.push_back(mesh.nodes[a]);
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        if (!keep[e]) continue;
        const Tet& t = mesh.tets[e];
        out.tets.push_back({new_index[t[0]], new_index[t[1]], new_index[t[2]], new_index[t[3]]});
        if (!mesh.tet_polyhedron.empty()) out.tet_polyhedron.push_back(mesh.tet_polyhedron[e]);
        tet_of.push_back(e);
    }
    compact_ids(out.tet_polyhedron);
    out.boundary = boundary_faces(out.tets);
    out.quality.elements = out.tet_count();
    return out;
}

void keep_old_tets(TetMesh& fresh, const TetMesh& old_mesh, std::span<const Index> old_node) {
    std::vector<Index> now(old_mesh.node_count(), -1);
    for (size_t a = 0; a < old_node.size(); ++a)
        if (old_node[a] >= 0) now[old_node[a]] = Index(a);
    std::vector<Tet> tets;
    for (const Tet& t : old_mesh.tets)
        if (std::all_of(t.begin(), t.end(), [&](Index a) { return now[a] >= 0; }))
            tets.push_back({now[t[0]], now[t[1]], now[t[2]], now[t[3]]});
    for (const Tet& t : fresh.tets)
        if (std::any_of(t.begin(), t.end(), [&](Index a) { return old_node[a] < 0; }))
            tets.push_back(t);
    fresh.tets = std::move(tets);
    // Each tet its own element: the EDT groups of the fresh mesh no longer apply.
    fresh.tet_polyhedron.resize(fresh.tets.size());
    std::iota(fresh.tet_polyhedron.begin(), fresh.tet_polyhedron.end(), Index(0));
    fresh.boundary = boundary_faces(fresh.tets);
    fresh.quality.elements = fresh.tet_count();
}

Index drop_tets_across_cracks(TetMesh& mesh, const TetMesh& old_mesh,
                              std::span<const ElementLink> old_links,
                              std::span<const Index> old_node, std::span<const char> on_crack) {
    if (std::find(on_crack.begin(), on_crack.end(), 1) == on_crack.end()) return 0;
    // Per old node: the tets it belongs to, and those with the tets linked to them.
    std::vector<std::vector<Index>> own(old_mesh.node_count()), near(old_mesh.node_count());
    for (Index e = 0; e < old_mesh.tet_count(); ++e)
        for (Index a : old_mesh.tets[e]) own[a].push_back(e), near[a].push_back(e);
    for (const ElementLink& l : old_links) {
        for (Index a : old_mesh.tets[l.a]) near[a].push_back(l.b);
        for (Index a : old_mesh.tets[l.b]) near[a].push_back(l.a);
    }
    for (std::vector<Index>& n : near) {
        std::sort(n.begin(), n.end());
        n.erase(std::unique(n.begin(), n.end()), n.end());
    }
    // Two crack nodes are on one side when a tet of one is, or is linked to, a tet of the other.
    const auto across = [&](Index a, Index b) {
        if (!on_crack[a] || !on_crack[b]) return false;
        const Index oa = old_node[a], ob = old_node[b];
        if (oa < 0 || ob < 0) return false;
        for (Index e : own[ob])
            if (std::binary_search(near[oa].begin(), near[oa].end(), e)) return false;
        return true;
    };
    std::vector<Tet> kept;
    std::vector<Index> kept_polyhedron;
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        const Tet& t = mesh.tets[e];
        bool closes = false;
        for (int i = 0; i < 4 && !closes; ++i)
            for (int k = i + 1; k < 4 && !closes; ++k) closes = across(t[i], t[k]);
        if (closes) continue;
        kept.push_back(t);
        if (!mesh.tet_polyhedron.empty()) kept_polyhedron.push_back(mesh.tet_polyhedron[e]);
    }
    const Index removed = mesh.tet_count() - Index(kept.size());
    if (removed == 0) return 0;
    mesh.tets = std::move(kept);
    if (!mesh.tet_polyhedron.empty()) mesh.tet_polyhedron = std::move(kept_polyhedron);
    compact_ids(mesh.tet_polyhedron);
    mesh.boundary = boundary_faces(mesh.tets);
    mesh.quality.elements = mesh.tet_count();
    return removed;
}

}  // namespace karst
