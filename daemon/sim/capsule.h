#pragma once

#include <Eigen/Core>

namespace everytouch::sim {

// A capsule (a segment swept by a sphere) seen through an affine map, so its cross-section can be an ellipse:
// finger bones about 16 mm wide and 12 mm thick, and with length 0 the ellipsoids of palm and thenar.
// Points X of the shape satisfy  X = origin + axes * L  for L in the unit capsule: the segment from (0, 0, 0)
// to (length, 0, 0) swept by the unit sphere.
struct Capsule {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();    // table mm
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: axis direction x cap radius, then the two
                                                         // cross-section semi-axes, mm
    double length = 0.0;                                 // axis length in units of the cap radius

    // A bone from `start` to `end` whose cross-section has semi-axes `sideRadius` along `side` and
    // `thicknessRadius` across it; the ends are capped with half-ellipsoids of axial radius `capRadius`.
    static Capsule bone(const Eigen::Vector3d& start, const Eigen::Vector3d& end, const Eigen::Vector3d& side,
                        double sideRadius, double thicknessRadius, double capRadius);
    // An ellipsoid with semi-axes `radii` along the columns of `rotation`.
    static Capsule ellipsoid(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& radii);

    Eigen::Vector3d axisEnd() const { return origin + axes.col(0) * length; }
    // The point of the surface farthest along `direction` (its support point): the lowest point for -z.
    Eigen::Vector3d supportPoint(const Eigen::Vector3d& direction) const;
};

// Ray intersection in the capsule's local frame, prepared once per capsule and ray origin. All rays of a
// pinhole device share the origin, so only the direction changes per pixel.
class CapsuleHit {
public:
    CapsuleHit(const Capsule& capsule, const Eigen::Vector3d& rayOrigin);

    // Smallest t > 0 with rayOrigin + t * direction on the surface, or a negative value for no hit.
    float intersect(const Eigen::Vector3f& direction) const { return intersectLocal(toLocal_ * direction); }
    float intersectLocal(const Eigen::Vector3f& localDirection) const;
    // Outward unit normal in the table frame at the hit `rayOrigin + t * direction`.
    Eigen::Vector3f normal(const Eigen::Vector3f& direction, float t) const;
    // The table-to-local linear map: a direction d becomes toLocal() * d.
    const Eigen::Matrix3f& toLocal() const { return toLocal_; }
    // Axial coordinate of a hit (0 at the capsule's start, `length` at its end), for texturing.
    float axial(const Eigen::Vector3f& direction, float t) const {
        return localOrigin_.x() + t * (toLocal_.row(0).dot(direction));
    }
    // Coordinate of a hit along the third axis (thickness), -1 .. 1: > 0 on the back of a finger.
    float dorsal(const Eigen::Vector3f& direction, float t) const {
        return localOrigin_.z() + t * (toLocal_.row(2).dot(direction));
    }

private:
    Eigen::Matrix3f toLocal_;
    Eigen::Matrix3f normalToTable_;
    Eigen::Vector3f localOrigin_;
    float length_;
};

}  // namespace everytouch::sim
