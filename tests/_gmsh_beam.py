"""The notched half beam written as a Gmsh mesh and read back as the user's own specimen (shared by the mesh
specimen's and the PF-CZM's tests)."""

from fracid.specimens.mesh import MeshSpecimen, write_gmsh


def beam_msh(beam, path, triangles=False):
    """The half beam's mesh written by write_gmsh (its node sets as groups) and described as a MeshSpecimen."""
    write_gmsh(beam.describe(), path, triangles=triangles)
    return MeshSpecimen(str(path), thickness=beam.thickness, supports=(("support", "y"),),
                        loads=(("loading_plate", "y", True, -0.5),), symmetry=(("ligament", "x"),),
                        controls=(("cmod", (("mouth", "x", 2.0),)), ("deflection", (("loading_plate", "y", -1.0),))),
                        symmetry_factor=2.0, crack=("ligament", "x", beam.h_fine))
