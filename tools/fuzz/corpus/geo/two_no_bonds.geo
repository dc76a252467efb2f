LSMGeometry 1.2
BoundingBox -1e3 -1e3 -1e3 1e3 1e3 1e3
PeriodicBoundaries 0 1 0
Dimension 3D
BeginParticles
Simple
2
1e2 -5 3.25e-1 0.75 -7 -2147483648
1e2 -4 3.25e-1 0.25 9223372036854775807 2147483647
EndParticles
