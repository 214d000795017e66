#include "sim/capsule.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace everytouch::sim {

Capsule Capsule::bone(const Eigen::Vector3d& start, const Eigen::Vector3d& end, const Eigen::Vector3d& side,
                      double sideRadius, double thicknessRadius, double capRadius) {
    const Eigen::Vector3d along = (end - start).normalized();
    const Eigen::Vector3d across = (side - along * along.dot(side)).normalized();
    const Eigen::Vector3d thickness = along.cross(across);
    Capsule capsule;
    capsule.origin = start;
    capsule.axes.col(0) = along * capRadius;
    capsule.axes.col(1) = across * sideRadius;
    capsule.axes.col(2) = thickness * thicknessRadius;
    capsule.length = (end - start).norm() / capRadius;
    return capsule;
}

Capsule Capsule::ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                           const Eigen::Vector3d& radii) {
    Capsule capsule;
    capsule.origin = centre;
    capsule.axes = rotation * radii.asDiagonal();
    capsule.length = 0.0;
    return capsule;
}

Eigen::Vector3d Capsule::supportPoint(const Eigen::Vector3d& direction) const {
    const Eigen::Vector3d spread = axes.transpose() * direction;
    const Eigen::Vector3d end = axisEnd();
    // Ties (a bone lying across the direction) resolve to the end: a fingertip rather than a knuckle.
    const Eigen::Vector3d& base = end.dot(direction) >= origin.dot(direction) - 1e-9 ? end : origin;
    const double norm = spread.norm();
    return norm > 0.0 ? Eigen::Vector3d(base + axes * spread / norm) : base;
}

CapsuleHit::CapsuleHit(const Capsule& capsule, const Eigen::Vector3d& rayOrigin) {
    const Eigen::Matrix3d inverse = capsule.axes.inverse();
    toLocal_ = inverse.cast<float>();
    normalToTable_ = inverse.transpose().cast<float>();
    localOrigin_ = (inverse * (rayOrigin - capsule.origin)).cast<float>();
    length_ = static_cast<float>(capsule.length);
}

float CapsuleHit::intersectLocal(const Eigen::Vector3f& d) const {
    const Eigen::Vector3f& o = localOrigin_;
    // Infinite cylinder y^2 + z^2 = 1 around the axis; every point of the capsule lies inside it.
    const float a = d.y() * d.y() + d.z() * d.z();
    const float b = o.y() * d.y() + o.z() * d.z();
    const float c = o.y() * o.y() + o.z() * o.z() - 1.0f;
    float capCentre;
    if (a > 1e-12f) {
        const float h = b * b - a * c;
        if (h < 0.0f)
            return -1.0f;
        const float t = (-b - std::sqrt(h)) / a;
        const float x = o.x() + t * d.x();
        if (x >= 0.0f && x <= length_)
            return t;
        capCentre = x < 0.0f ? 0.0f : length_;
    } else {
        if (c > 0.0f)
            return -1.0f;
        // Along the axis: the cap facing the ray.
        capCentre = (d.x() > 0.0f) == (o.x() < 0.0f) ? 0.0f : length_;
        if (o.x() >= 0.0f && o.x() <= length_)
            capCentre = d.x() > 0.0f ? length_ : 0.0f;
    }
    const Eigen::Vector3f oc(o.x() - capCentre, o.y(), o.z());
    const float dd = d.squaredNorm();
    const float bs = oc.dot(d);
    const float hs = bs * bs - dd * (oc.squaredNorm() - 1.0f);
    if (hs < 0.0f)
        return -1.0f;
    return (-bs - std::sqrt(hs)) / dd;
}

Eigen::Vector3f CapsuleHit::normal(const Eigen::Vector3f& direction, float t) const {
    const Eigen::Vector3f p = localOrigin_ + t * (toLocal_ * direction);
    const float axisX = std::clamp(p.x(), 0.0f, length_);
    const Eigen::Vector3f local(p.x() - axisX, p.y(), p.z());
    return (normalToTable_ * local).normalized();
}

}  // namespace everytouch::sim
