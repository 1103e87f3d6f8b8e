// Half of the notched beam of Gregoire, Rojas-Solano & Pijaudier-Cabot (2013) in three-point bending,
// the same geometry as fracid's NotchedBeam() defaults (src/fracid/specimens/beam.py), for fracid's
// [specimen] type = "mesh" (see README.md and identify.toml beside this file).
//
// The beam is symmetric about mid-span: only x >= 0 is meshed. Lengths in mm.
//
//     y
//     ^ loading_plate (0 <= x <= plate/2, y = D)
//  D  +==+------------------------------------------------+
//     |                                                   |
//     | <- ligament (x = 0, a0 <= y <= D): symmetry line, |
//     |    the crack runs along it                        |
//  a0 +-+                                                 |
//       | <- notch flank (x = notch/2), free              |
//   0   o--------------------------------[===^===]--------+--> x
//     mouth (notch/2, 0)          support (S/2 +- plate/2), L/2
//                                 support_point ^ (S/2, 0)
//
// Mesh it with
//     gmsh half_beam.geo -2 -format msh22 -o half_beam.msh

D = 50.0;        // depth
L = 175.0;       // length
S = 125.0;       // span
a0 = 25.0;       // notch depth
notch = 2.0;     // notch width (the half model holds notch/2 of it)
plate = 5.0;     // width of the loading plate and of each support plate

// element sizes; override them on the command line, e.g. gmsh half_beam.geo -2 -setnumber h_fine 1 ...
DefineConstant[
  h_fine = 2.0,       // element size along the ligament (the process zone)
  fine_width = 10.0,  // h_fine up to this distance from the ligament ...
  h_far = 10.0,       // ... growing to this size 30 mm further
  h_plate = 1.25      // at the support plate (plate/4, as the built-in beam: the reaction concentrates at its edges)
];

// corner points (the characteristic lengths are overridden by the size field below)
Point(1) = {notch/2, 0, 0};        // notch mouth
Point(2) = {S/2 - plate/2, 0, 0};  // support plate, left end
Point(3) = {S/2 + plate/2, 0, 0};  // support plate, right end
Point(4) = {L/2, 0, 0};
Point(5) = {L/2, D, 0};
Point(6) = {plate/2, D, 0};        // loading plate, right end
Point(7) = {0, D, 0};              // mid-span, top
Point(8) = {0, a0, 0};             // notch tip on the symmetry line
Point(9) = {notch/2, a0, 0};       // notch tip corner
Point(10) = {S/2, 0, 0};           // support plate, centre (a roller for the open-crack models)

Line(1) = {1, 2};   // bottom, free
Line(2) = {2, 10};  // support plate, left half
Line(10) = {10, 3}; // support plate, right half
Line(3) = {3, 4};   // bottom, free
Line(4) = {4, 5};   // end of the beam, free
Line(5) = {5, 6};   // top, free
Line(6) = {6, 7};   // loading plate
Line(7) = {7, 8};   // ligament (symmetry line above the notch, the crack line)
Line(8) = {8, 9};   // notch tip, free
Line(9) = {9, 1};   // notch flank, free

Curve Loop(1) = {1, 2, 10, 3, 4, 5, 6, 7, 8, 9};
Plane Surface(1) = {1};

// element size: h_fine within fine_width of the ligament, growing to h_far; h_plate at the support
Field[1] = Distance;
Field[1].CurvesList = {7};
Field[1].Sampling = 100;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_fine;
Field[2].SizeMax = h_far;
Field[2].DistMin = fine_width;
Field[2].DistMax = fine_width + 30.0;
Field[3] = Distance;
Field[3].CurvesList = {2, 10};
Field[3].Sampling = 20;
Field[4] = Threshold;
Field[4].InField = 3;
Field[4].SizeMin = h_plate;
Field[4].SizeMax = h_far;
Field[4].DistMin = 0.0;
Field[4].DistMax = 25.0;
Field[5] = Min;
Field[5].FieldsList = {2, 4};
Background Field = 5;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Mesh.Algorithm = 6;       // Frontal-Delaunay triangles
Mesh.RecombineAll = 0;    // triangles only: fracid needs one element family per mesh
Mesh.ElementOrder = 1;    // fracid adds the mid-edge nodes itself (T6)
Mesh.SaveAll = 0;         // save only the physical groups: no orphan nodes

// the names fracid's identify.toml refers to
Physical Surface("domain") = {1};
Physical Curve("ligament") = {7};       // symmetry: u_x = 0
Physical Curve("support") = {2, 10};    // u_y = 0 over the support plate
Physical Point("support_point") = {10}; // u_y = 0 at its centre only: the support of the open-crack models
Physical Curve("loading_plate") = {6};  // rigid plate carrying the load; its y displacement is the deflection
Physical Point("mouth") = {1};          // CMOD = 2 u_x(mouth)
