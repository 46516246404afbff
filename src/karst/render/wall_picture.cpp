#include "karst/render/wall_picture.hpp"

#include "karst/scene/scene.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace karst {

namespace {

/// The scene's shape types by Shape::Kind (read back by read_shape).
constexpr const char* k_kind_names[] = {"box", "sphere", "cylinder", "union", "difference"};

nlohmann::json point(const Vec3& p) {
    return nlohmann::json::array({p[0], p[1], p[2]});
}

nlohmann::json shape_to_json(const Shape& s) {
    nlohmann::json j{{"type", k_kind_names[int(s.kind)]}};
    switch (s.kind) {
        case Shape::Kind::Box:
            j["min"] = point(s.a), j["max"] = point(s.b);
            break;
        case Shape::Kind::Sphere:
            j["center"] = point(s.a), j["radius"] = s.radius;
            break;
        case Shape::Kind::Cylinder:
            j["base"] = point(s.a), j["top"] = point(s.b), j["radius"] = s.radius;
            break;
        case Shape::Kind::Union:
        case Shape::Kind::Difference:
            j["shapes"] = nlohmann::json::array();
            for (const Shape& c : s.children) j["shapes"].push_back(shape_to_json(c));
            break;
    }
    return j;
}

std::string vec(const Vec3& v) {
    return fmt::format("<{:.9g},{:.9g},{:.9g}>", v[0], v[1], v[2]);
}

/// The shape grown by `t` (shrunk for t < 0): boxes and radii move out, cylinders also along
/// their axis; a difference grows its first shape and shrinks what it takes away. Empty where
/// shrinking leaves nothing.
std::string pov_shape(const Shape& s, Real t) {
    switch (s.kind) {
        case Shape::Kind::Box: {
            const Vec3 lo = s.a.array() - t, hi = s.b.array() + t;
            if ((hi.array() <= lo.array()).any()) return {};
            return fmt::format("box {{ {}, {} }}", vec(lo), vec(hi));
        }
        case Shape::Kind::Sphere:
            if (s.radius + t <= 0) return {};
            return fmt::format("sphere {{ {}, {:.9g} }}", vec(s.a), s.radius + t);
        case Shape::Kind::Cylinder: {
            const Vec3 axis = (s.b - s.a).normalized();
            if (s.radius + t <= 0 || (s.b - s.a).norm() + 2 * t <= 0) return {};
            return fmt::format("cylinder {{ {}, {}, {:.9g} }}", vec(s.a - t * axis),
                               vec(s.b + t * axis), s.radius + t);
        }
        case Shape::Kind::Union:
        case Shape::Kind::Difference: {
            const bool difference = s.kind == Shape::Kind::Difference;
            std::string members;
            for (size_t k = 0; k < s.children.size(); ++k) {
                const std::string child = pov_shape(s.children[k], difference && k > 0 ? -t : t);
                if (difference && k == 0 && child.empty()) return {};
                if (!child.empty()) members += child + " ";
            }
            if (members.empty()) return {};
            return (difference ? "difference { " : "union { ") + members + "}";
        }
    }
    return {};
}

}  // namespace

nlohmann::json walls_to_json(const std::vector<PicturedWall>& walls) {
    nlohmann::json j = nlohmann::json::array();
    for (const PicturedWall& w : walls)
        j.push_back({{"shape", shape_to_json(w.shape)},
                     {"container", w.container},
                     {"thickness", w.thickness}});
    return j;
}

std::vector<PicturedWall> walls_from_json(const nlohmann::json& j) {
    std::vector<PicturedWall> walls;
    for (size_t i = 0; i < j.size(); ++i) {
        const nlohmann::json& w = j.at(i);
        walls.push_back({read_shape(w.at("shape"), fmt::format("/walls/{}/shape", i)),
                         w.at("container").get<bool>(), w.at("thickness").get<Real>()});
    }
    return walls;
}

std::string pov_walls(const std::vector<PicturedWall>& walls, const Vec3& camera) {
    std::string pov;
    for (const PicturedWall& w : walls) {
        const std::string shape = pov_shape(w.shape, 0);
        if (shape.empty()) continue;
        if (!w.container) {
            pov += fmt::format(
                "object {{ {} pigment {{ srgb <0.62,0.6,0.57> }} finish {{ diffuse 0.85 }} }}\n",
                shape);
            continue;
        }
        // A cut-away tank: the shell outside the held space's box on each side the camera
        // looks from is left out (for a box, the near walls and the lid), so the camera sees in.
        const Aabb box = w.shape.bounds();
        std::string cuts;
        // Each cut is a box beyond one face of the held space's box, reaching a little into it
        // (where there is no shell) so that no two faces coincide.
        const Aabb outer = box.padded(w.thickness + box.max.maxCoeff() - box.min.minCoeff() + 1);
        const Real inset = 1e-3 * (box.max - box.min).maxCoeff();
        auto cut = [&](int d, bool low) {
            Aabb c = outer;
            (low ? c.max : c.min)[d] = low ? box.min[d] + inset : box.max[d] - inset;
            cuts += fmt::format(" box {{ {}, {} }}", vec(c.min), vec(c.max));
        };
        for (int d = 0; d < 3; ++d) {
            if (camera[d] < box.min[d]) cut(d, true);
            if (camera[d] > box.max[d]) cut(d, false);
        }
        pov += fmt::format(
            "difference {{ {} {}{} pigment {{ srgb <0.8,0.82,0.84> }} finish {{ diffuse 0.8 "
            "specular 0.1 }} }}\n",
            pov_shape(w.shape, w.thickness), shape, cuts);
    }
    return pov;
}

}  // namespace karst
