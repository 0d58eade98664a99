#include <gtest/gtest.h>

#include "globemesh/sphere.hpp"

using namespace globemesh;

TEST(Sphere, poles_and_equator_are_exact) {
    EXPECT_EQ(lonlat_to_vec(0, 90), (Vec3{0, 0, 1}));
    EXPECT_EQ(lonlat_to_vec(123.4, -90).z, -1.0);
    EXPECT_EQ(lonlat_to_vec(90, 0), (Vec3{0, 1, 0}));
    EXPECT_EQ(lonlat_to_vec(-180, 0), (Vec3{-1, 0, 0}));
    EXPECT_EQ(lonlat_to_vec(37.5, 0).z, 0.0);
}

TEST(Sphere, lonlat_round_trip) {
    for (double lon = -179.5; lon < 180; lon += 7.3)
        for (double lat = -89.5; lat <= 89.5; lat += 3.1) {
            LonLat p = vec_to_lonlat(lonlat_to_vec(lon, lat));
            EXPECT_NEAR(p.lon, lon, 1e-12);
            EXPECT_NEAR(p.lat, lat, 1e-12);
        }
    EXPECT_EQ(vec_to_lonlat(lonlat_to_vec(180, 10)).lon, -180.0); // longitudes in [-180, 180)
}

TEST(Sphere, arc_angle_matches_haversine_and_is_accurate_when_tiny) {
    Vec3 a = lonlat_to_vec(0, 0), b = lonlat_to_vec(90, 0);
    EXPECT_NEAR(arc_angle(a, b), pi / 2, 1e-15);
    Vec3 c = lonlat_to_vec(1e-9, 0);
    EXPECT_NEAR(arc_angle(a, c), 1e-9 * deg_to_rad, 1e-24);
    EXPECT_NEAR(arc_km(lonlat_to_vec(0, 0), lonlat_to_vec(0, 1)), earth_radius_km * deg_to_rad,
                1e-9);
}

// Along the equator from lon 0 to 40: a point at latitude phi above the arc is phi away (the
// meridian through it meets the arc at a right angle); beyond an end it is its distance to that
// end; on the arc it is 0.
TEST(Sphere, arc_distance_is_to_the_great_circle_between_the_ends_and_to_an_end_beyond) {
    const Vec3 a = lonlat_to_vec(0, 0), b = lonlat_to_vec(40, 0);
    EXPECT_NEAR(arc_distance(a, b, lonlat_to_vec(15, 0)), 0, 1e-15);
    EXPECT_NEAR(arc_distance(a, b, lonlat_to_vec(15, 12)), 12 * deg_to_rad, 1e-15);
    EXPECT_NEAR(arc_distance(a, b, lonlat_to_vec(25, -30)), 30 * deg_to_rad, 1e-15);
    const Vec3 beyond = lonlat_to_vec(50, 5);
    EXPECT_DOUBLE_EQ(arc_distance(a, b, beyond), arc_angle(b, beyond));
    EXPECT_DOUBLE_EQ(arc_distance(b, a, beyond), arc_angle(b, beyond)); // either direction
    const Vec3 before = lonlat_to_vec(-20, -3);
    EXPECT_DOUBLE_EQ(arc_distance(a, b, before), arc_angle(a, before));
    EXPECT_DOUBLE_EQ(arc_distance(a, a, before), arc_angle(a, before)); // a zero-length arc
}

// Along the equator the line goes straight on; turning north at lon 10 along the meridian is a
// right angle either way round; going back is pi; a repeated point does not turn.
TEST(Sphere, turn_angle_is_the_angle_between_the_two_great_circles) {
    const Vec3 a = lonlat_to_vec(0, 0), b = lonlat_to_vec(10, 0);
    EXPECT_NEAR(turn_angle(a, b, lonlat_to_vec(20, 0)), 0, 1e-7);
    EXPECT_NEAR(turn_angle(a, b, lonlat_to_vec(10, 15)), pi / 2, 1e-15);
    EXPECT_NEAR(turn_angle(a, b, lonlat_to_vec(10, -15)), pi / 2, 1e-15);
    EXPECT_NEAR(turn_angle(a, b, lonlat_to_vec(5, 0)), pi, 1e-7);
    // The meridian lon 10 from the pole, then the small-circle-free turn onto lon 10 + 30: at
    // the pole two meridians meet at their longitude difference.
    const Vec3 pole{0, 0, 1};
    EXPECT_NEAR(turn_angle(lonlat_to_vec(10, 40), pole, lonlat_to_vec(190 + 30, 40)),
                30 * deg_to_rad, 1e-12);
    EXPECT_EQ(turn_angle(a, a, b), 0);
}

TEST(Sphere, octant_triangle_area_is_an_eighth_of_the_sphere) {
    double area = spherical_triangle_area({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
    EXPECT_NEAR(area, 4 * pi / 8, 1e-15);
    EXPECT_NEAR(spherical_triangle_area({1, 0, 0}, {0, 0, 1}, {0, 1, 0}), -4 * pi / 8, 1e-15);
}

TEST(Sphere, quality_is_one_for_equilateral_and_zero_for_degenerate) {
    EXPECT_NEAR(triangle_quality({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1.0, 1e-15);
    EXPECT_NEAR(triangle_quality({1, 0, 0}, {1, 0, 0}, {0, 0, 1}), 0.0, 1e-15);
}

TEST(Sphere, midpoint_is_equidistant) {
    Vec3 a = lonlat_to_vec(-20, 10), b = lonlat_to_vec(40, 50);
    Vec3 m = arc_midpoint(a, b);
    EXPECT_NEAR(arc_angle(a, m), arc_angle(m, b), 1e-15);
    Vec3 q = arc_interpolate(a, b, 0.25);
    EXPECT_NEAR(arc_angle(a, q), 0.25 * arc_angle(a, b), 1e-14);
}
