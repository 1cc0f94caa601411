"""The benchmark sheet of issue 11 item 4, written for each solver.

1 m x 1 m flat sheet in the z = 0 plane, t = 1 mm, E = 1 GPa, nu = 0.3, isotropic prestress
1 MPa, all edge nodes pinned (u = 0), n x n nodes, each cell split into two triangles along
the same diagonal (counter-clockwise seen from +z), uniform pressure 0 -> 1 kPa pushing
towards +z, raised linearly over 5 equal load steps of one increment each.

Standard library only. `python3 sheet.py N OUTDIR` writes every solver's input for one size.
"""

import json
import os
import sys

SIDE = 1.0  # m
THICKNESS = 1e-3  # m
YOUNG = 1e9  # Pa
POISSON = 0.3
PRESTRESS = 1e6  # Pa, both in-plane directions, no shear
PRESSURE = 1e3  # Pa, towards +z
STEPS = 5


def mesh(n):
    """Nodes [(x, y, 0)], triangles (0-based, counter-clockwise from +z), boundary node
    indices and the centre node index (n odd: the node at (0.5, 0.5))."""
    if n < 3 or n % 2 == 0:
        raise ValueError(f"n = {n}: the sheet needs an odd n >= 3 (a node at the centre)")
    h = SIDE / (n - 1)
    nodes = [(i * h, j * h, 0.0) for j in range(n) for i in range(n)]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b = j * n + i, j * n + i + 1
            c, d = b + n, a + n
            tris.append((a, b, c))
            tris.append((a, c, d))
    boundary = [j * n + i for j in range(n) for i in range(n)
                if i in (0, n - 1) or j in (0, n - 1)]
    centre = (n // 2) * n + n // 2
    return nodes, tris, boundary, centre


def write_ours(n, path):
    """Our model file (docs/model-format.md): pinned edges as supports, a follower pressure."""
    nodes, tris, boundary, centre = mesh(n)
    model = {
        "name": f"Sheet{n}",
        "description": f"issue 11 item 4 benchmark sheet, {n} x {n} nodes",
        "nodes": [list(p) for p in nodes],
        "triangles": [list(t) for t in tris],
        "material": {"youngs_modulus": YOUNG, "poisson_ratio": POISSON,
                     "thickness": THICKNESS, "prestress": [PRESTRESS, PRESTRESS, 0.0]},
        "supports": [{"node": v, "fixed": ["x", "y", "z"]} for v in boundary],
        "loads": {"pressures": [{"name": "p", "elements": "all", "pressure": PRESSURE}]},
        "outputs": {"points": [{"name": "centre", "node": centre}]},
    }
    with open(path, "w") as f:
        json.dump(model, f, separators=(",", ":"))


def write_kratos(n, stem):
    """Kratos: stem.mdpa (MembraneElement3D3N, SurfaceLoadCondition3D3N on every triangle),
    stem_materials.json (PRESTRESS_VECTOR) and stem_parameters.json (static, non-linear,
    5 steps of 0.2, NEGATIVE_FACE_PRESSURE = 1000 t: a follower pressure along +z for
    counter-clockwise triangles, with its load stiffness)."""
    nodes, tris, boundary, centre = mesh(n)
    with open(stem + ".mdpa", "w") as f:
        f.write("Begin ModelPartData\nEnd ModelPartData\n\n")
        f.write("Begin Properties 0\nEnd Properties\n\n")
        f.write("Begin Nodes\n")
        f.writelines(f"{k + 1} {x:.17g} {y:.17g} {z:.17g}\n" for k, (x, y, z) in enumerate(nodes))
        f.write("End Nodes\n\nBegin Elements MembraneElement3D3N\n")
        f.writelines(f"{k + 1} 0 {a + 1} {b + 1} {c + 1}\n" for k, (a, b, c) in enumerate(tris))
        f.write("End Elements\n\nBegin Conditions SurfaceLoadCondition3D3N\n")
        f.writelines(f"{k + 1} 0 {a + 1} {b + 1} {c + 1}\n" for k, (a, b, c) in enumerate(tris))
        f.write("End Conditions\n\n")
        ids = "".join(f"{k + 1}\n" for k in range(len(nodes)))
        eids = "".join(f"{k + 1}\n" for k in range(len(tris)))
        f.write("Begin SubModelPart membrane\n Begin SubModelPartNodes\n" + ids
                + " End SubModelPartNodes\n Begin SubModelPartElements\n" + eids
                + " End SubModelPartElements\nEnd SubModelPart\n\n")
        f.write("Begin SubModelPart edges\n Begin SubModelPartNodes\n"
                + "".join(f"{v + 1}\n" for v in boundary) + " End SubModelPartNodes\nEnd SubModelPart\n\n")
        f.write("Begin SubModelPart pressure\n Begin SubModelPartNodes\n" + ids
                + " End SubModelPartNodes\n Begin SubModelPartConditions\n" + eids
                + " End SubModelPartConditions\nEnd SubModelPart\n\n")
        f.write(f"Begin SubModelPart centre\n Begin SubModelPartNodes\n{centre + 1}\n"
                " End SubModelPartNodes\nEnd SubModelPart\n")
    materials = {"properties": [{
        "model_part_name": "Structure.membrane", "properties_id": 1,
        "Material": {"constitutive_law": {"name": "LinearElasticPlaneStress2DLaw"},
                     "Variables": {"THICKNESS": THICKNESS, "DENSITY": 0.0,
                                   "YOUNG_MODULUS": YOUNG, "POISSON_RATIO": POISSON,
                                   "PRESTRESS_VECTOR": [PRESTRESS, PRESTRESS, 0.0]},
                     "Tables": {}}}]}
    with open(stem + "_materials.json", "w") as f:
        json.dump(materials, f, indent=1)
    dt = 1.0 / STEPS
    params = {
        "problem_data": {"problem_name": os.path.basename(stem), "parallel_type": "OpenMP",
                         "echo_level": 0, "start_time": 0.0, "end_time": 1.0},
        "solver_settings": {
            "solver_type": "Static", "model_part_name": "Structure", "domain_size": 3,
            "echo_level": 1, "analysis_type": "non_linear",
            "model_import_settings": {"input_type": "mdpa", "input_filename": stem},
            "material_import_settings": {"materials_filename": stem + "_materials.json"},
            "time_stepping": {"time_step": dt},
            "line_search": False,
            "convergence_criterion": "and_criterion",
            "displacement_relative_tolerance": 1e-5, "displacement_absolute_tolerance": 1e-12,
            "residual_relative_tolerance": 1e-5, "residual_absolute_tolerance": 1e-9,
            "max_iteration": 50, "rotation_dofs": False,
            "linear_solver_settings": {"solver_type": "LinearSolversApplication.sparse_lu"},
        },
        "processes": {
            "constraints_process_list": [{
                "python_module": "assign_vector_variable_process",
                "kratos_module": "KratosMultiphysics",
                "Parameters": {"model_part_name": "Structure.edges", "variable_name": "DISPLACEMENT",
                               "constrained": [True, True, True], "value": [0.0, 0.0, 0.0],
                               "interval": [0.0, "End"]}}],
            "loads_process_list": [{
                "python_module": "assign_scalar_variable_to_conditions_process",
                "kratos_module": "KratosMultiphysics",
                "Parameters": {"model_part_name": "Structure.pressure",
                               "variable_name": "NEGATIVE_FACE_PRESSURE",
                               "value": f"{PRESSURE}*t", "interval": [0.0, "End"]}}],
            "list_other_processes": [],
        },
        "output_processes": {},
    }
    with open(stem + "_parameters.json", "w") as f:
        json.dump(params, f, indent=1)


def write_ccx(n, path, element="S3"):
    """CalculiX: S3 shells (or M3D3 membranes), NLGEOM, the prestress as *INITIAL CONDITIONS,
    TYPE=STRESS at every integration point of the expanded elements, edges pinned (DOFs 1-3),
    *DLOAD P = +1 kPa on every element (pushes towards +z for these counter-clockwise
    triangles; a follower load with NLGEOM, its load stiffness left out: ccx factors a symmetric matrix), 5 fixed increments of 0.2, the
    centre's displacement printed to the .dat file."""
    nodes, tris, boundary, centre = mesh(n)
    points = 2  # integration points of the C3D6 wedge an S3/M3D3 is expanded into
    with open(path, "w") as f:
        f.write("*HEADING\nissue 11 item 4 benchmark sheet\n*NODE, NSET=NALL\n")
        f.writelines(f"{k + 1}, {x:.17g}, {y:.17g}, {z:.17g}\n" for k, (x, y, z) in enumerate(nodes))
        f.write(f"*ELEMENT, TYPE={element}, ELSET=EALL\n")
        f.writelines(f"{k + 1}, {a + 1}, {b + 1}, {c + 1}\n" for k, (a, b, c) in enumerate(tris))
        f.write("*NSET, NSET=EDGES\n")
        f.writelines(f"{v + 1},\n" for v in boundary)
        f.write(f"*NSET, NSET=CENTRE\n{centre + 1},\n")
        f.write("*MATERIAL, NAME=FILM\n*ELASTIC\n"
                f"{YOUNG:.6e}, {POISSON}\n")
        kind = "SHELL" if element.startswith("S") else "MEMBRANE"
        f.write(f"*{kind} SECTION, ELSET=EALL, MATERIAL=FILM\n{THICKNESS}\n")
        f.write("*BOUNDARY\nEDGES, 1, 3\n")
        f.write("*INITIAL CONDITIONS, TYPE=STRESS\n")
        s = f"{PRESTRESS:.6e}, {PRESTRESS:.6e}, 0., 0., 0., 0.\n"
        for k in range(len(tris)):
            for ip in range(points):
                f.write(f"{k + 1}, {ip + 1}, {s}")
        f.write(f"*STEP, NLGEOM, INC=1000\n*STATIC, DIRECT\n{1.0 / STEPS}, 1.0\n")
        # Residual and correction tolerances of 1e-5 (ccx's defaults: 0.005 and 0.01), as ours.
        f.write("*CONTROLS, PARAMETERS=FIELD\n1e-5, 1e-5\n")
        f.write(f"*DLOAD\nEALL, P, {PRESSURE}\n")
        f.write("*NODE PRINT, NSET=CENTRE\nU\n*NODE PRINT, NSET=EDGES, TOTALS=ONLY\nRF\n")
        f.write("*END STEP\n")


def write_all(n, outdir):
    """Every solver's input for the n x n sheet in outdir; returns their paths."""
    os.makedirs(outdir, exist_ok=True)
    ours = os.path.join(outdir, f"sheet{n}.json")
    kratos = os.path.join(outdir, f"sheet{n}_kratos")
    ccx = os.path.join(outdir, f"sheet{n}_ccx.inp")
    write_ours(n, ours)
    write_kratos(n, kratos)
    write_ccx(n, ccx)
    return {"ours": ours, "kratos": kratos, "ccx": ccx}


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: sheet.py N OUTDIR")
    print(write_all(int(sys.argv[1]), sys.argv[2]))
