// A 3 m x 2 m ETFE film laid flat at the crown height of two parallel circular arches
// (span 2.4 m, rise 0.3 m, 0.8 m apart, in the planes y = 0.6 and y = 1.4).
// The arch lines are embedded in the film surface so that the mesh has film nodes right
// above each arch: the physical curves "arch_south" and "arch_north" select them.
//
//   gmsh -2 -format msh22 film_over_two_arches.geo -o film_over_two_arches_v22.msh
//   gmsh -2 -format msh41 -bin film_over_two_arches.geo -o film_over_two_arches_v41_bin.msh
//
// Physical groups (mapped by name in mapping.json):
//   film        surface   the whole film (output element set)
//   frame       curves    the four edges (boundary group, lowered by the crown height / 2)
//   arch_south  curve     film nodes above the arch at y = 0.6 (gaps S1..S13)
//   arch_north  curve     film nodes above the arch at y = 1.4 (gaps N1..N13)
//   centre      point     the film's centre (output point)

H = 0.3;      // crown height = arch rise (m): the film lies flat at z = H
lc = 0.2;     // element size (m): coarse, about 300 triangles

Point(1) = {0, 0, H, lc};
Point(2) = {3, 0, H, lc};
Point(3) = {3, 2, H, lc};
Point(4) = {0, 2, H, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// projections of the arches on the film (from foot to foot, x = 0.3 .. 2.7)
Point(5) = {0.3, 0.6, H, lc};
Point(6) = {2.7, 0.6, H, lc};
Point(7) = {0.3, 1.4, H, lc};
Point(8) = {2.7, 1.4, H, lc};
Line(5) = {5, 6};
Line(6) = {7, 8};
Point(9) = {1.5, 1.0, H, lc};
Curve{5, 6} In Surface{1};
Point{9} In Surface{1};

Physical Surface("film") = {1};
Physical Curve("frame") = {1, 2, 3, 4};
Physical Curve("arch_south") = {5};
Physical Curve("arch_north") = {6};
Physical Point("centre") = {9};
