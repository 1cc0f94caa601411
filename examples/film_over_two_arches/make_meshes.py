"""Regenerates the checked-in meshes from film_over_two_arches.geo with gmsh's Python module
(``pip install gmsh``; the PyPI wheel 4.15.2 wrote the files in this folder):

    python make_meshes.py

writes film_over_two_arches_v22.msh (gmsh 2.2 ASCII) and film_over_two_arches_v41_bin.msh
(gmsh 4.1 binary) from the same mesh, so that both import to the same model.
"""

from pathlib import Path

import gmsh

HERE = Path(__file__).resolve().parent

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(str(HERE / "film_over_two_arches.geo"))
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write(str(HERE / "film_over_two_arches_v22.msh"))
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write(str(HERE / "film_over_two_arches_v41_bin.msh"))
gmsh.finalize()
