// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The modeling language: every construct builds the field its factory builds, bindings and
// comments, scans loaded once through the callback, and errors at the exact line and column.

#include "pointform/implicit/scene.h"

#include "pointform/core/error.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/transform.h"

#include "support/test_support.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

namespace pointform {
namespace {

using FieldPtr = std::shared_ptr<const Field>;

FieldPtr parse(std::string_view text)
{
    return parse_scene(text).field;
}

/// The message of the InvalidInput that parsing `text` throws ("" and a test failure if none).
std::string error_of(std::string_view text, const SceneOptions& options = {})
{
    try
    {
        (void)parse_scene(text, options);
    }
    catch (const InvalidInput& e)
    {
        return e.what();
    }
    ADD_FAILURE() << "no error for: " << text;
    return "";
}

/// Compares two fields at the points of a 7×7×7 grid over [-2, 2]³.
void expect_same_field(const Field& parsed, const Field& expected)
{
    std::size_t compared = 0;
    for (int i = 0; i < 7; ++i)
    {
        for (int j = 0; j < 7; ++j)
        {
            for (int k = 0; k < 7; ++k)
            {
                const Vec3d p(-2.0 + 0.6 * i + 0.013, -2.0 + 0.6 * j + 0.029, -2.0 + 0.6 * k);
                const FieldSample a = parsed.evaluate(p);
                const FieldSample b = expected.evaluate(p);
                ASSERT_EQ(a.defined, b.defined) << p.transpose();
                ASSERT_NEAR(a.value, b.value, 1e-12 * (1.0 + std::abs(b.value))) << p.transpose();
                ASSERT_LT((a.gradient - b.gradient).norm(), 1e-9) << p.transpose();
                ++compared;
            }
        }
    }
    EXPECT_EQ(compared, 343U);
    const Aabb ab = parsed.bounds();
    const Aabb bb = expected.bounds();
    for (int axis = 0; axis < 3; ++axis)
    {
        EXPECT_EQ(ab.min[axis], bb.min[axis]);
        EXPECT_EQ(ab.max[axis], bb.max[axis]);
    }
}

TEST(Scene, SphereEvaluatesLikeMakeSphere)
{
    const FieldPtr parsed = parse("sphere([0, 0, 0], 1)");
    ASSERT_TRUE(parsed);
    expect_same_field(*parsed, *make_sphere(Vec3d::Zero(), 1.0));
    // And it is the unit sphere: zero on it, −1 at the centre.
    EXPECT_NEAR(parsed->evaluate(Vec3d(0.6, 0.8, 0.0)).value, 0.0, 1e-15);
    EXPECT_NEAR(parsed->evaluate(Vec3d(0.0, 0.0, 0.0)).value, -1.0, 1e-15);
}

TEST(Scene, EveryPrimitiveMatchesItsFactory)
{
    expect_same_field(*parse("box([-1, -0.5, -0.25], [1, 0.5, 0.75])"),
                      *make_box(Vec3d(-1, -0.5, -0.25), Vec3d(1, 0.5, 0.75)));
    expect_same_field(*parse("box([-1, -0.5, -0.25], [1, 0.5, 0.75], rounded = 0.1)"),
                      *make_box(Vec3d(-1, -0.5, -0.25), Vec3d(1, 0.5, 0.75), 0.1));
    const Mat3d r =
        Eigen::AngleAxisd(std::numbers::pi / 6.0, Vec3d(1, 1, 0).normalized()).toRotationMatrix();
    expect_same_field(
        *parse("oriented_box([0.1, 0, 0], [1, 0.5, 0.3], axis = [1, 1, 0], degrees = 30, "
               "rounded = 0.05)"),
        *make_oriented_box(Vec3d(0.1, 0, 0), Vec3d(1, 0.5, 0.3), r, 0.05));
    expect_same_field(*parse("oriented_box([0, 0, 0], [1, 0.5, 0.3])"),
                      *make_oriented_box(Vec3d::Zero(), Vec3d(1, 0.5, 0.3), Mat3d::Identity()));
    expect_same_field(*parse("cylinder([0, 0, -1], [0, 0.5, 1], 0.4)"),
                      *make_cylinder(Vec3d(0, 0, -1), Vec3d(0, 0.5, 1), 0.4));
    expect_same_field(*parse("cone([0, 0, -1], [0, 0, 1], 0.8)"),
                      *make_cone(Vec3d(0, 0, -1), Vec3d(0, 0, 1), 0.8, 0.0));
    expect_same_field(*parse("cone([0, 0, -1], [0, 0, 1], 0.8, radius_b = 0.2)"),
                      *make_cone(Vec3d(0, 0, -1), Vec3d(0, 0, 1), 0.8, 0.2));
    expect_same_field(*parse("torus([0, 0, 0], [0, 1, 0], 1, 0.25)"),
                      *make_torus(Vec3d::Zero(), Vec3d(0, 1, 0), 1.0, 0.25));
    expect_same_field(*parse("half_space([0, 0, 0.5], [0, 0, 2])"),
                      *make_half_space(Vec3d(0, 0, 0.5), Vec3d(0, 0, 2)));
}

TEST(Scene, OperatorsAndTransformsMatchTheirFactories)
{
    const FieldPtr a = make_sphere(Vec3d::Zero(), 1.0);
    const FieldPtr b = make_sphere(Vec3d(1, 0, 0), 0.5);
    const FieldPtr c = make_box(Vec3d(-0.2, -0.2, -2), Vec3d(0.2, 0.2, 2));
    const std::string sa = "sphere([0, 0, 0], 1)";
    const std::string sb = "sphere([1, 0, 0], 0.5)";
    const std::string sc = "box([-0.2, -0.2, -2], [0.2, 0.2, 2])";
    expect_same_field(*parse("union(" + sa + ", " + sb + ")"), *make_union({a, b}));
    expect_same_field(*parse("union(" + sa + ", " + sb + ", " + sc + ")"), *make_union({a, b, c}));
    expect_same_field(*parse("intersection(" + sa + ", " + sb + ")"), *make_intersection({a, b}));
    expect_same_field(*parse("difference(" + sa + ", " + sb + ")"), *make_difference(a, b));
    expect_same_field(*parse("difference(" + sa + ", " + sb + ", " + sc + ")"),
                      BooleanField(BooleanOp::Difference, {a, b, c}));
    expect_same_field(*parse("smooth_union(" + sa + ", " + sb + ", radius = 0.2)"),
                      *make_smooth_union(a, b, 0.2));
    expect_same_field(*parse("smooth_intersection(" + sa + ", " + sb + ", 0.2)"),
                      *make_smooth_intersection(a, b, 0.2));
    expect_same_field(*parse("smooth_difference(" + sa + ", " + sb + ", 0.2)"),
                      *make_smooth_difference(a, b, 0.2));
    expect_same_field(*parse("blend(" + sa + ", " + sb + ", range = 0.3)"),
                      *make_blend(BlendKind::Linear, {a, b}, 0.3));
    expect_same_field(*parse("blend(" + sa + ", " + sb + ", range = 0.3, kind = \"hyperbolic\")"),
                      *make_blend(BlendKind::Hyperbolic, {a, b}, 0.3));
    expect_same_field(*parse("blend(" + sa + ", " + sb + ", " + sc +
                             ", kind = \"super_elliptic\", beta = 3, range = 0.3)"),
                      *make_blend(BlendKind::SuperElliptic, {a, b, c}, 0.3, 3.0));
    expect_same_field(*parse("offset(" + sa + ", -0.25)"), *make_offset(a, -0.25));
    expect_same_field(*parse("shell(" + sa + ", 0.1)"), *make_shell(a, 0.1));
    expect_same_field(*parse("morph(" + sa + ", " + sb + ", 0.25)"), *make_morph(a, b, 0.25));
    expect_same_field(*parse("translate(" + sa + ", [0.5, -1, 2])"),
                      *translate(a, Vec3d(0.5, -1, 2)));
    expect_same_field(*parse("rotate(" + sc + ", axis = [1, 0, 0], degrees = 90)"),
                      *rotate(c, Vec3d(1, 0, 0), std::numbers::pi / 2.0));
    expect_same_field(*parse("rotate(" + sc + ", [0, 1, 0], 45, center = [1, 0, 0])"),
                      *rotate(c, Vec3d(0, 1, 0), std::numbers::pi / 4.0, Vec3d(1, 0, 0)));
    expect_same_field(*parse("scale(" + sb + ", 2)"), *scale(b, 2.0));
    expect_same_field(*parse("scale(" + sb + ", [1, 2, 0.5], center = [1, 0, 0])"),
                      *scale(b, Vec3d(1, 2, 0.5), Vec3d(1, 0, 0)));
}

TEST(Scene, DifferenceOfTwoSpheresHasTheBooleanValue)
{
    const FieldPtr field = parse("difference(sphere([0, 0, 0], 1), sphere([1, 0, 0], 0.5))");
    for (const Vec3d& p : {Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(-0.5, 0.2, 0), Vec3d(0.7, 0.1, 0),
                           Vec3d(2, 2, 2), Vec3d(0.6, 0.0, 0.3)})
    {
        const double fa = p.norm() - 1.0;
        const double fb = (p - Vec3d(1, 0, 0)).norm() - 0.5;
        EXPECT_NEAR(field->evaluate(p).value, std::max(fa, -fb), 1e-14) << p.transpose();
    }
    // The bite: the centre of the cut-away sphere is outside, the far side of A inside.
    EXPECT_GT(field->evaluate(Vec3d(1, 0, 0)).value, 0.0);
    EXPECT_LT(field->evaluate(Vec3d(-0.5, 0, 0)).value, 0.0);
}

TEST(Scene, NumbersInEveryForm)
{
    // Centre (−0.5, 0.001, 2), radius 0.5: written with a sign, an exponent, a leading '+',
    // a leading '.'.
    const FieldPtr field = parse("sphere([-0.5, 1e-3, +2], .5)");
    EXPECT_NEAR(field->evaluate(Vec3d(-0.5, 0.001, 2)).value, -0.5, 1e-15);
    EXPECT_NEAR(field->evaluate(Vec3d(-0.5, 0.001, 2.5)).value, 0.0, 1e-15);
    const FieldPtr other = parse("sphere([1E+1, -2.5e-1, 3.], 25e-2)");
    EXPECT_NEAR(other->evaluate(Vec3d(10, -0.25, 3)).value, -0.25, 1e-15);
}

TEST(Scene, BindingsCommentsAndSeparators)
{
    const std::string text = R"(# a scene with every kind of statement
let r = 0.5            # a number bound to a name
center = [1, 0, 0]     # 'let' is optional
let a = sphere([0, 0, 0], 1); let b = sphere(center, r)

# an expression may span lines inside parentheses
result = difference(
    a,   # the body
    b,   # the bite
)
)";
    const FieldPtr field = parse(text);
    expect_same_field(*field, *make_difference(make_sphere(Vec3d::Zero(), 1.0),
                                               make_sphere(Vec3d(1, 0, 0), 0.5)));
    // A final expression instead of `result = ...`, with CRLF line ends and a name reused.
    const FieldPtr crlf =
        parse("let a = sphere([0,0,0], 1)\r\nunion(a, translate(a, [1,0,0]))\r\n");
    expect_same_field(*crlf,
                      *make_union({make_sphere(Vec3d::Zero(), 1.0),
                                   translate(make_sphere(Vec3d::Zero(), 1.0), Vec3d(1, 0, 0))}));
}

TEST(Scene, NestedExpressions)
{
    const FieldPtr field = parse(
        "offset(rotate(difference(union(sphere([0,0,0],1), box([0,0,0],[1.5,0.2,0.2])), "
        "scale(sphere([0,0,0],0.5), [1,1,3])), axis=[0,0,1], degrees=90), 0.05)");
    const FieldPtr expected = make_offset(
        rotate(make_difference(make_union({make_sphere(Vec3d::Zero(), 1.0),
                                           make_box(Vec3d::Zero(), Vec3d(1.5, 0.2, 0.2))}),
                               scale(make_sphere(Vec3d::Zero(), 0.5), Vec3d(1, 1, 3))),
               Vec3d(0, 0, 1), std::numbers::pi / 2.0),
        0.05);
    expect_same_field(*field, *expected);
}

TEST(Scene, ScansAreResolvedAndLoadedOnce)
{
    test::TempDir dir;
    test::write_file(dir / "a.ply", "");
    test::write_file(dir / "b.ply", "");
    std::vector<std::string> loaded;
    SceneOptions options;
    options.base_directory = dir.path();
    options.load_scan = [&loaded](const std::string& path) -> FieldPtr {
        loaded.push_back(path);
        return make_sphere(Vec3d::Zero(), 1.0);
    };
    const Scene scene = parse_scene(
        "let unused = scan(\"b.ply\")\n"
        "union(scan(\"a.ply\"), translate(scan(\"./a.ply\"), [1, 0, 0]), scan(\"" +
            (dir / "a.ply").string() + "\"))",
        options);
    ASSERT_EQ(loaded.size(), 1U);
    EXPECT_EQ(std::filesystem::path(loaded[0]), (dir.path() / "a.ply").lexically_normal());
    ASSERT_EQ(scene.scans.size(), 1U);
    EXPECT_EQ(scene.scans[0], loaded[0]);
    // The loader's field is what the scene uses.
    EXPECT_NEAR(scene.field->evaluate(Vec3d(0, 0, 0)).value, -1.0, 1e-12);
}

TEST(Scene, ReadSceneResolvesScansAgainstItsDirectory)
{
    test::TempDir dir;
    std::filesystem::create_directories(dir / "data");
    test::write_file(dir / "data" / "part.xyz", "");
    test::write_file(dir / "scene.pf",
                     "# scene\nlet part = scan(\"data/part.xyz\")\n"
                     "smooth_union(part, sphere([0, 1.6, 0], 0.5), radius = 0.3)\n");
    std::string loaded;
    const Scene scene =
        read_scene(dir / "scene.pf", [&loaded](const std::string& path) -> FieldPtr {
            loaded = path;
            return make_sphere(Vec3d::Zero(), 1.0);
        });
    EXPECT_EQ(std::filesystem::path(loaded), (dir.path() / "data" / "part.xyz").lexically_normal());
    EXPECT_LT(scene.field->evaluate(Vec3d(0, 1.05, 0)).value, 0.0); // the fillet fills the gap
    // Errors name the file.
    test::write_file(dir / "bad.pf", "let a = sphere([0,0,0], 1)\nunion(a, b)\n");
    try
    {
        (void)read_scene(dir / "bad.pf");
        ADD_FAILURE() << "no error";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_EQ(std::string(e.what()), (dir / "bad.pf").string() +
                                             ":2:10: undefined name 'b' (bind it first: 'let b "
                                             "= ...')");
    }
    EXPECT_THROW((void)read_scene(dir / "missing.pf"), IoError);
}

TEST(Scene, LooksLikeFile)
{
    test::TempDir dir;
    test::write_file(dir / "scene.pf", "sphere([0,0,0],1)");
    EXPECT_TRUE(looks_like_file((dir / "scene.pf").string()));
    EXPECT_FALSE(looks_like_file("sphere([0,0,0],1)"));
    EXPECT_FALSE(looks_like_file((dir / "nothere.pf").string()));
    EXPECT_FALSE(looks_like_file(""));
}

TEST(SceneErrors, UnbalancedParentheses)
{
    EXPECT_EQ(error_of("union(sphere([0,0,0],1), sphere([1,0,0],1)"),
              "expression:1:43: expected ',' or ')' after argument 2 of union, found end of "
              "input (the '(' at 1:6 is not closed)");
    EXPECT_EQ(error_of("sphere([0,0,0],1))"),
              "expression:1:18: unexpected ')' after the expression: no '(' is open");
    EXPECT_EQ(error_of("sphere([0,0,0)"),
              "expression:1:14: expected ',' or ']' after component 3 of the vector, found ')'");
    EXPECT_EQ(error_of("sphere([0,0"),
              "expression:1:12: expected ',' or ']' after component 2 of the vector, found end "
              "of input (the '[' at 1:8 is not closed)");
}

TEST(SceneErrors, MissingComma)
{
    EXPECT_EQ(error_of("sphere([0,0,0] 1)"),
              "expression:1:16: expected ',' or ')' after argument 1 of sphere, found '1'");
    SceneOptions options;
    options.source_name = "scene.pf";
    EXPECT_EQ(error_of("# a ball\nlet r = 1\nlet s = sphere([0, 0, 0], r x)\ns\n", options),
              "scene.pf:3:29: expected ',' or ')' after argument 2 of sphere, found 'x'");
    EXPECT_EQ(error_of("sphere([0 0 0], 1)"),
              "expression:1:11: expected ',' or ']' after component 1 of the vector, found '0'");
}

TEST(SceneErrors, UnknownFunctionSuggestsTheClosest)
{
    EXPECT_EQ(error_of("sphre([0,0,0],1)"),
              "expression:1:1: unknown function 'sphre'; did you mean 'sphere'?");
    EXPECT_EQ(error_of("union(sphere([0,0,0],1),\n  smooth_unoin(sphere([0,0,0],1), "
                       "sphere([1,0,0],1), 0.1))"),
              "expression:2:3: unknown function 'smooth_unoin'; did you mean 'smooth_union'?");
    EXPECT_EQ(error_of("smooth([0,0,0],1)"),
              "expression:1:1: unknown function 'smooth'; did you mean 'smooth_union'?");
    EXPECT_EQ(error_of("plane([0,0,0],[0,0,1])"),
              "expression:1:1: unknown function 'plane'; did you mean 'half_space'?");
    const std::string unknown = error_of("frobnicate(1)");
    EXPECT_EQ(unknown.rfind("expression:1:1: unknown function 'frobnicate' (known functions: scan, "
                            "sphere, box,",
                            0),
              0U)
        << unknown;
}

TEST(SceneErrors, WrongArgumentCount)
{
    EXPECT_EQ(error_of("sphere([0,0,0], 1, 2)"),
              "expression:1:20: too many arguments to sphere: it takes 2, sphere(center, radius)");
    EXPECT_EQ(error_of("sphere([0,0,0])"),
              "expression:1:15: missing argument 'radius' of sphere(center, radius)");
    EXPECT_EQ(error_of("union(sphere([0,0,0],1))"),
              "expression:1:24: union needs at least 2 fields, found 1 (union(a, b, ...))");
    EXPECT_EQ(error_of("blend(sphere([0,0,0],1), sphere([1,0,0],1))"),
              "expression:1:43: missing argument 'range' of blend(a, ..., range, kind = "
              "\"linear\", beta = 2)");
    EXPECT_EQ(error_of("sphere([0,0,0], radius = 1, radius = 2)"),
              "expression:1:29: argument 'radius' of sphere is given twice");
    EXPECT_EQ(error_of("sphere(radius = 1, [0,0,0])"),
              "expression:1:20: positional argument 2 of sphere after a keyword argument: "
              "positional arguments come first");
}

TEST(SceneErrors, WrongType)
{
    EXPECT_EQ(error_of("sphere(1, 1)"),
              "expression:1:8: argument 'center' of sphere must be a vector [x, y, z], found a "
              "number");
    EXPECT_EQ(error_of("offset(1, 1)"),
              "expression:1:8: argument 'a' of offset must be a field (a shape), found a number");
    EXPECT_EQ(error_of("let c = [0,0,0]\nunion(sphere(c, 1), c)"),
              "expression:2:21: argument 2 of union must be a field, found a vector [x, y, z] "
              "(union(a, b, ...))");
    EXPECT_EQ(error_of("blend(sphere([0,0,0],1), 0.1)"),
              "expression:1:26: argument 2 of blend must be a field, found a number (blend(a, "
              "..., range, kind = \"linear\", beta = 2); its other parameters are given by "
              "keyword, e.g. range = ...)");
    EXPECT_EQ(error_of("sphere([0, sphere([0,0,0],1), 0], 1)"),
              "expression:1:12: component 2 of a vector must be a number, found a field (a shape)");
    EXPECT_EQ(error_of("scan(1)"),
              "expression:1:6: argument 'path' of scan must be a string \"...\", found a number");
    EXPECT_EQ(error_of("let r = 1\nr"),
              "expression:2:1: the scene's result must be a field (a shape), found a number");
}

TEST(SceneErrors, ValuesOutOfRange)
{
    EXPECT_EQ(error_of("sphere([0,0,0], -1)"),
              "expression:1:17: argument 'radius' of sphere must be > 0, found -1");
    EXPECT_EQ(error_of("morph(sphere([0,0,0],1), sphere([0,0,0],2), 1.5)"),
              "expression:1:45: argument 't' of morph must be in [0, 1], found 1.5");
    EXPECT_EQ(error_of("blend(sphere([0,0,0],1), sphere([1,0,0],1), range = 0.1, kind = "
                       "\"hyperbolik\")"),
              "expression:1:65: argument 'kind' of blend must be \"linear\", \"hyperbolic\" or "
              "\"super_elliptic\", found \"hyperbolik\"; did you mean 'hyperbolic'?");
    EXPECT_EQ(error_of("blend(sphere([0,0,0],1), sphere([1,0,0],1), range = 0.1, beta = 0.5)"),
              "expression:1:65: argument 'beta' of blend must be ≥ 1, found 0.5");
    EXPECT_EQ(error_of("scale(sphere([0,0,0],1), [1, 0, 1])"),
              "expression:1:26: argument 'factor' of scale must be > 0 in every component, "
              "found [1, 0, 1]");
    EXPECT_EQ(error_of("rotate(sphere([0,0,0],1), [0,0,0], 10)"),
              "expression:1:27: argument 'axis' of rotate must be a non-zero vector, found [0, 0, "
              "0]");
    EXPECT_EQ(error_of("smooth_union(sphere([0,0,0],1), sphere([1,0,0],1), radus = 0.1)"),
              "expression:1:52: smooth_union has no parameter 'radus'; did you mean 'radius'? "
              "(smooth_union(a, b, radius))");
    // What only the factory can check comes with the call's position.
    const std::string rounding = error_of("\n  box([0,0,0], [1,1,1], rounded = 0.8)");
    EXPECT_EQ(rounding.rfind("expression:2:3: box: rounding radius", 0), 0U) << rounding;
    const std::string apart = error_of("morph(sphere([0,0,0],1), sphere([10,0,0],1), 0.5)");
    EXPECT_EQ(apart.rfind("expression:1:1: morph: ", 0), 0U) << apart;
}

TEST(SceneErrors, UndefinedNamesAndBindings)
{
    EXPECT_EQ(error_of("let ball = sphere([0,0,0],1)\nunion(bal, ball)"),
              "expression:2:7: undefined name 'bal'; did you mean 'ball'?");
    EXPECT_EQ(error_of("let a = union(a, sphere([0,0,0],1))\na"),
              "expression:1:15: undefined name 'a' (bind it first: 'let a = ...')");
    EXPECT_EQ(error_of("union(sphere, box([0,0,0],[1,1,1]))"),
              "expression:1:7: 'sphere' is a function; call it as sphere(center, radius)");
    EXPECT_EQ(error_of("let a = 1\nlet a = 2\nsphere([0,0,0], a)"),
              "expression:2:5: 'a' is already bound at 1:5; choose another name");
    EXPECT_EQ(error_of("let box = 1\nsphere([0,0,0], box)"),
              "expression:1:5: 'box' is a function's name; choose another name for the binding");
    EXPECT_EQ(error_of("let = sphere([0,0,0],1)"),
              "expression:1:5: expected a name after 'let', found '='");
    EXPECT_EQ(error_of("let a sphere([0,0,0],1)"),
              "expression:1:7: expected '=' after 'let a', found 'sphere'");
    EXPECT_EQ(error_of("let a = \nsphere([0,0,0],1)"),
              "expression:1:9: expected an expression after 'a =', found end of line");
}

TEST(SceneErrors, TrailingGarbageAndStatements)
{
    EXPECT_EQ(error_of("sphere([0,0,0],1) x"),
              "expression:1:19: expected end of line or ';' after the expression, found 'x'");
    EXPECT_EQ(error_of("let a = sphere([0,0,0],1) b"),
              "expression:1:27: expected end of line or ';' after the binding of 'a', found 'b'");
    EXPECT_EQ(error_of("sphere([0,0,0],1)\nsphere([1,0,0],1)"),
              "expression:1:1: only the last statement is the scene's result; bind this "
              "expression to a name ('let name = ...') or remove it");
    EXPECT_EQ(error_of("let a = sphere([0,0,0],1)\n"),
              "expression:2:1: expected the scene's result (an expression, or 'result = ...') "
              "after the binding of 'a', found end of input");
    EXPECT_EQ(error_of("result = sphere([0,0,0],1)\nlet b = 1\nresult"),
              "expression:1:1: 'result' names the scene's result and must be the last statement");
}

TEST(SceneErrors, EmptyInput)
{
    EXPECT_EQ(error_of(""),
              "expression:1:1: empty scene: expected an expression, found end of "
              "input");
    EXPECT_EQ(error_of("  # nothing but a comment\n\n"),
              "expression:3:1: empty scene: expected an expression, found end of input");
}

TEST(SceneErrors, Tokens)
{
    EXPECT_EQ(error_of("sphere([0,0,0], 1e)"),
              "expression:1:18: expected the digits of an exponent after '1e'");
    EXPECT_EQ(error_of("sphere([0,0,0], -r)"),
              "expression:1:17: expected a number after '-' (the language has no arithmetic; "
              "write the value)");
    EXPECT_EQ(error_of("sphere([0,0,0], 1e999)"),
              "expression:1:17: the number '1e999' is out of range");
    EXPECT_EQ(error_of("scan(\"bunny.ply)"),
              "expression:1:6: unterminated string: expected a closing '\"' before end of input");
    // Columns count characters, not bytes.
    EXPECT_EQ(error_of("# é\nsphere([0,0,0], é)"), "expression:2:17: unexpected character 'é'");
    EXPECT_EQ(error_of("scan(\"ü\") @"), "expression:1:11: unexpected character '@'");
    EXPECT_EQ(error_of("sphere([0,0], 1)"),
              "expression:1:8: a vector has 3 components [x, y, z], found 2");
    EXPECT_EQ(error_of("sphere([0,0,0,0], 1)"),
              "expression:1:15: a vector has 3 components [x, y, z]; found a 4th");
}

TEST(SceneErrors, ScansAreCheckedBeforeAnyIsLoaded)
{
    test::TempDir dir;
    test::write_file(dir / "a.ply", "");
    std::size_t calls = 0;
    SceneOptions options;
    options.base_directory = dir.path();
    options.load_scan = [&calls](const std::string&) -> FieldPtr {
        ++calls;
        return make_sphere(Vec3d::Zero(), 1.0);
    };
    // An error after the scan is found before the scan is loaded.
    EXPECT_EQ(error_of("let a = scan(\"a.ply\")\nunion(a, sphere([0,0,0], 0))", options),
              "expression:2:26: argument 'radius' of sphere must be > 0, found 0");
    const std::string missing = error_of("union(scan(\"a.ply\"), scan(\"nothere.ply\"))", options);
    EXPECT_EQ(missing.rfind("expression:1:27: scan file not found: '" +
                                (dir.path() / "nothere.ply").lexically_normal().string() + "'",
                            0),
              0U)
        << missing;
    EXPECT_EQ(calls, 0U);
    // No loader: scan() is refused.
    EXPECT_EQ(error_of("scan(\"a.ply\")"),
              "expression:1:1: scan(\"a.ply\") is not available here (no scan loader)");
    // What the loader throws gets the call's position.
    options.load_scan = [](const std::string&) -> FieldPtr {
        throw InvalidInput("too few points");
    };
    EXPECT_EQ(error_of("scan(\"a.ply\")", options),
              "expression:1:1: scan(\"a.ply\"): too few points");
}

// ---------------------------------------------------------------------------------------------
// Hostile scenes: deep nesting, and bindings shared along exponentially many paths

TEST(SceneHostile, NestingDeeperThan256IsAnErrorAtTheOpeningThatExceedsIt)
{
    std::string deep;
    for (int i = 0; i < 20000; ++i)
    {
        deep += "union(";
    }
    // The 257th '(' stands at column 6 · 257.
    const std::string message = error_of(deep);
    EXPECT_EQ(message.rfind("expression:1:1542: nested too deep: more than 256", 0), 0U) << message;

    std::string brackets = "sphere(";
    for (int i = 0; i < 5000; ++i)
    {
        brackets += "[";
    }
    EXPECT_EQ(error_of(brackets).rfind("expression:1:263: nested too deep", 0), 0U)
        << error_of(brackets);

    // 250 levels are fine, and mean what they say.
    std::string moved = "sphere([0, 0, 0], 1)";
    for (int i = 0; i < 250; ++i)
    {
        moved = "translate(" + moved + ", [0.01, 0, 0])";
    }
    const FieldPtr field = parse(moved);
    EXPECT_NEAR(field->evaluate(Vec3d(3.5, 0.0, 0.0)).value, 0.0, 1e-9);
}

TEST(SceneHostile, BindingsNestedDeeperThan256AreAnErrorAtTheirLineAndColumn)
{
    std::string text = "let a0 = sphere([0, 0, 0], 1)\n";
    for (int i = 1; i <= 300; ++i)
    {
        text += "let a" + std::to_string(i) + " = translate(a" + std::to_string(i - 1) +
                ", [0.01, 0, 0])\n";
    }
    text += "a300\n";
    // a0 is a primitive (1); a_i nests i + 1 deep: a256 is the first too deep, on line 257.
    const std::string message = error_of(text);
    EXPECT_EQ(message.rfind("expression:257:12: translate nests the scene's field too deep", 0), 0U)
        << message;
}

TEST(SceneHostile, SharedBindingsAreEvaluatedOncePerPoint)
{
    // 40 levels of union(a, a): 2^40 paths, 41 distinct nodes.
    std::string text = "let a0 = sphere([0.1, 0.2, 0.3], 1)\n";
    for (int i = 1; i < 40; ++i)
    {
        text += "let a" + std::to_string(i) + " = union(a" + std::to_string(i - 1) + ", a" +
                std::to_string(i - 1) + ")\n";
    }
    text += "translate(a39, [1, 0, 0])\n";
    const auto start = std::chrono::steady_clock::now();
    const FieldPtr field = parse(text);
    const FieldPtr expected = translate(make_sphere(Vec3d(0.1, 0.2, 0.3), 1.0), Vec3d::UnitX());
    expect_same_field(*field, *expected);
    std::vector<Vec3d> points;
    for (int i = 0; i < 5000; ++i)
    {
        points.emplace_back(0.001 * i - 2.5, std::sin(i), std::cos(0.5 * i));
    }
    std::vector<FieldSample> batch(points.size());
    field->evaluate(points, batch);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        ASSERT_EQ(batch[i].value, expected->evaluate(points[i]).value);
    }
    std::vector<Vec3d> seeds;
    field->append_seeds(seeds);
    std::vector<Vec3d> sphere_seeds;
    expected->append_seeds(sphere_seeds);
    EXPECT_EQ(seeds.size(), sphere_seeds.size());
    EXPECT_LT(field->cost(), 100.0); // linear in the distinct nodes, not 2^40
    // Without sharing this would take 2^40 evaluations per point; with it, well under a second
    // (a generous bound for loaded machines).
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              20.0);
}

TEST(SceneHostile, SharedBindingsKeepTheirValuesInEveryUse)
{
    // One binding used at different points (through a transform) and at the same ones.
    const FieldPtr field = parse(
        "let a = box([-1, -1, -1], [1, 1, 1])\n"
        "let b = union(a, translate(a, [1.5, 0, 0]), a)\n"
        "difference(b, translate(b, [0, 0, 1.8]), b)");
    const FieldPtr a = make_box(Vec3d::Constant(-1.0), Vec3d::Constant(1.0));
    const FieldPtr b = make_union({a, translate(a, Vec3d(1.5, 0, 0)), a});
    const FieldPtr expected = std::make_shared<const BooleanField>(
        BooleanOp::Difference, std::vector<FieldPtr>{b, translate(b, Vec3d(0, 0, 1.8)), b});
    expect_same_field(*field, *expected);
}

TEST(Scene, FunctionSummaryListsEveryFunction)
{
    const std::string summary = scene_function_summary();
    for (const std::string name :
         {"scan(path)", "sphere(center, radius)", "box(min, max, rounded = 0)", "union(a, b, ...)",
          "blend(a, ..., range, kind = \"linear\", beta = 2)", "morph(a, b, t)",
          "rotate(a, axis, degrees, center = [0, 0, 0])"})
    {
        EXPECT_NE(summary.find(name + "\n"), std::string::npos) << name;
    }
}

} // namespace
} // namespace pointform
