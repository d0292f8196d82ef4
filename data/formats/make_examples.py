#!/usr/bin/env python3
"""Writes the example exports in this folder, data/formats/ (run from anywhere: python3 make_examples.py).

Every number is made up here, from one analytic deformation of a flat 7 x 7 grid of
points 5 mm apart (X, Y in [-15, 15] mm, Z = 0):

    x = Q (lambda1 X, lambda2 Y, 0) + c,   lambda1 = 1.10 (along X), lambda2 = 0.95 (along Y),
    Q = rotation of 10 deg about X after 20 deg about Z,   c = (2, -1, 3) mm,

a homogeneous in-plane stretch plus a rigid motion: the exact strains at every point are
E1 = (1.10^2 - 1)/2 = 0.105, E2 = (0.95^2 - 1)/2 = -0.04875 (true strains ln 1.10 =
0.0953102, ln 0.95 = -0.0512933). The stage series scales it: at stage time t (s, 0 to
10), lambda1 = 1 + 0.010 t, lambda2 = 1 - 0.005 t, the angles and c times t / 10.

Each file is written in the layout of one measuring system's export, as described in the
research notes the readers were built from, with 2-3 points marked invalid the way that
system marks them. They imitate the layouts only: preamble lines, extra columns and their
values are invented, and no file here comes from the systems themselves.
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
N = 7
PITCH = 5.0


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def deform(X, t=10.0):
    """Current position of reference point X at stage time t (t = 10: the full deformation)."""
    s = t / 10.0
    l1, l2 = 1.0 + 0.010 * t, 1.0 - 0.005 * t
    q = matmul(rot_x(math.radians(10.0 * s)), rot_z(math.radians(20.0 * s)))
    y = apply(q, [l1 * X[0], l2 * X[1], X[2]])
    return [y[0] + 2.0 * s, y[1] - 1.0 * s, y[2] + 3.0 * s]


def points():
    """(i, j, X) of the grid, row by row: i along Y, j along X."""
    for i in range(N):
        for j in range(N):
            yield i, j, [(j - 3) * PITCH, (i - 3) * PITCH, 0.0]


def f6(v):
    return f"{v:.6f}"


def e_matchid(v):
    """MatchID's number style: 5 decimals and a 3-digit exponent (6.68633E-001)."""
    m, e = f"{v:.5E}".split("E")
    return f"{m}E{int(e):+04d}"


def write(name, text):
    path = os.path.join(HERE, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def gom_rows(t, skip=(), empty=()):
    rows = []
    for i, j, X in points():
        pid = i * N + j + 1
        if pid in skip:
            continue
        x = deform(X, t)
        u = [x[k] - X[k] for k in range(3)]
        if pid in empty:
            rows.append(";".join([str(pid)] + [""] * 8))
            continue
        eps = [100 * (1.0 + 0.010 * t - 1), 100 * (1.0 - 0.005 * t - 1)]
        rows.append(";".join([str(pid)] + [f6(v) for v in x + u] + [f"{eps[0]:.4f}", f"{eps[1]:.4f}"]))
    return rows


GOM_HEADER = ("id;x [mm];y [mm];z [mm];displacement_x [mm];displacement_y [mm];displacement_z [mm];"
              "epsilon_x [%, technical];epsilon_y [%, technical]")


def gom_file(t, skip=(), empty=()):
    return "\n".join([
        "# GOM-style surface component export, written by hand for gsa's tests (made-up numbers)",
        "Project;demo plate 7x7",
        "Stage;Time [s];Force [kN]",
        f"{int(round(t))};{t:.3f};{1.84 * t:.2f}",
        "",
        GOM_HEADER,
    ] + gom_rows(t, skip, empty)) + "\n"


def gom_correlate_file(t, skip=()):
    """The layout of a real GOM Correlate / ARAMIS surface-component CSV export, line for
    line as one was seen (a DP800 tensile test, data/real/README.md): a units line, the
    stage as a comment and as a one-row table, the component's name, then ids from 0 and
    columns without units, 4 decimals. Its German installation wrote 'Stufe' and
    'Flächenkomponente'; strains in %, mises_strain and thickness_strain from the true
    strains (made up like the rest)."""
    l1, l2 = 1.0 + 0.010 * t, 1.0 - 0.005 * t
    p1, p2 = math.log(l1), math.log(l2)
    p3 = -(p1 + p2)
    mises = math.sqrt(2.0 / 3.0 * (p1 * p1 + p2 * p2 + p3 * p3))
    rows = []
    for i, j, X in points():
        pid = i * N + j
        if pid in skip:
            continue
        x = deform(X, t)
        u = [x[k] - X[k] for k in range(3)]
        strains = [100 * (l1 - 1), 100 * (l2 - 1), 100 * mises, 100 * p3]
        rows.append(";".join([str(pid)] + [f"{v:.4f}" for v in x + u + strains]))
    return "\n".join([
        "# Units: length:mm angle:deg time:s ",
        "# Stage: Stufe 11",
        "stage;index;relative_time;date",
        f'"Stufe 11";11;{t:.4f};"2023-02-10T13:54:06.849"',
        "# Name : Flächenkomponente 1",
        "id;x;y;z;displacement_x;displacement_y;displacement_z;epsilon_x;epsilon_y;mises_strain;thickness_strain",
    ] + rows) + "\n"


def main():
    # The layout of a real GOM Correlate surface-component export (units line, no units
    # in the names, ids from 0); points 8 and 32 are left out of the stage.
    write("gom_correlate_stage.csv", gom_correlate_file(10.0, skip=(8, 32)))

    # GOM/ZEISS: ';', a comment and a second table before the header, current positions
    # plus displacements, percent strains with a comma inside the unit brackets. Points 9
    # and 33 are left out of the stage (lost by the system), 17 and 41 have empty cells.
    write("gom_stage.csv", gom_file(10.0, skip=(9, 33), empty=(17, 41)))
    # The same stage as a German-locale export might write it: decimal commas (the ';'
    # delimiter leaves the comma free). Whether GOM software does so is not confirmed.
    text = gom_file(10.0, skip=(9, 33), empty=(17, 41))
    lines = text.split("\n")
    head_at = lines.index(GOM_HEADER)
    lines = [line.replace(".", ",") if k > head_at or 0 < k < head_at - 1 else line for k, line in enumerate(lines)]
    write("gom_stage_decimal_comma.csv", "\n".join(lines))
    # The same as a series: the reference stage and two stages, one file each.
    write("gom_series/surface-1_0.000s.csv", gom_file(0.0))
    write("gom_series/surface-1_2.000s.csv", gom_file(2.0, empty=(17,)))
    write("gom_series/surface-1_10.000s.csv", gom_file(10.0, skip=(9, 33)))

    # MatchID 2024.1 names: the image position of the subset centre is the key, coor.* the
    # reference positions (the preset's assumption), disp.* the displacements. Point 25
    # has nan displacements, 2 and 48 are left out.
    head = ["Coordinates.Image X [Pixel]", "Coordinates.Image Y [Pixel]", "coor.X [mm]", "coor.Y [mm]",
            "coor.Z [mm]", "disp.Horizontal Displacement U [mm]", "disp.Vertical Displacement V [mm]",
            "disp.Out-Of-Plane: W [mm]", "strain.Strain-global frame: Exx [ ]", "stats.Sigma [mm]",
            "ext.Time [s]"]
    rows = [",".join(head)]
    for i, j, X in points():
        pid = i * N + j + 1
        if pid in (2, 48):
            continue
        x = deform(X)
        u = [x[k] - X[k] for k in range(3)]
        cells = [str(800 + 25 * j), str(900 - 25 * i)] + [e_matchid(v) for v in X]
        cells += ["NaN"] * 3 if pid == 25 else [e_matchid(v) for v in u]
        cells += [e_matchid(0.105), e_matchid(0.0010 + 0.0001 * (pid % 5)), e_matchid(10.0)]
        rows.append(",".join(cells))
    write("matchid_image.csv", "\n".join(rows) + "\n")

    # MatchID 2023 names: no units in the header (mm and dimensionless), key x_pic, y_pic
    # on a 10 px step, rows in the order of the seed growth (not raster order). Points 1
    # and 37 are left out.
    rows = ["x_pic,y_pic,x,y,z,u,v,w,exx,eyy,exy,e1,e2,gamma,evm"]
    grid = list(points())
    order = sorted(grid, key=lambda p: (abs(p[0] - 3) + abs(p[1] - 3), p[0], p[1]))
    for i, j, X in order:
        pid = i * N + j + 1
        if pid in (1, 37):
            continue
        x = deform(X)
        u = [x[k] - X[k] for k in range(3)]
        cells = [str(610 + 10 * j), str(700 - 10 * i)] + [e_matchid(v) for v in X + u]
        cells += [e_matchid(v) for v in (0.105, -0.04875, 0.0, 0.105, -0.04875, 0.0, 0.11)]
        rows.append(",".join(cells))
    write("matchid_2023_image.csv", "\n".join(rows) + "\n")

    # VIC-3D: quoted names padded with spaces; X, Y, Z reference positions, U, V, W
    # displacements, sigma in pixels; x, y the subset in the reference image (the key).
    # Points 5, 23 and 44 failed: a row of zeros with sigma = -1, x and y kept.
    names = ["X", "Y", "Z", "U", "V", "W", "exx", "eyy", "exy", "sigma", "x", "y"]
    rows = [",".join(f'  "{n}"' for n in names)[1:]]
    for i, j, X in points():
        pid = i * N + j + 1
        xp, yp = 300 + 21 * j, 420 + 21 * i
        if pid in (5, 23, 44):
            rows.append(",".join(["0"] * 9 + ["-1", str(xp), str(yp)]))
            continue
        x = deform(X)
        u = [x[k] - X[k] for k in range(3)]
        sigma = 0.004 + 0.001 * (pid % 3)
        rows.append(",".join([f6(v) for v in X + u] + ["0.105", "-0.04875", "0", f"{sigma:.4f}", str(xp), str(yp)]))
    write("vic3d_frame.csv", "\n".join(rows) + "\n")

    # DICe: a preamble of lines starting with ***, then the header; stereo results in
    # model coordinates. Subsets 6, 30 and 40 failed: SIGMA = GAMMA = MATCH = -1,
    # STATUS_FLAG a failure code, their displacements left as they were (stale).
    pre = ["***",
           "*** DICe-style solution file, written by hand for gsa's tests (made-up numbers)",
           "***",
           "*** Reference image: ref_0000.tif",
           "*** Deformed image: def_0010.tif",
           "*** Subset size: 31",
           "*** Step size: x 20 y 20 (-1 implies not regular grid)",
           "*** Coordinates given with (0,0) as upper left corner of image, x positive right, y positive down",
           "***"]
    head = ["SUBSET_ID", "COORDINATE_X", "COORDINATE_Y", "MODEL_COORDINATES_X", "MODEL_COORDINATES_Y",
            "MODEL_COORDINATES_Z", "MODEL_DISPLACEMENT_X", "MODEL_DISPLACEMENT_Y", "MODEL_DISPLACEMENT_Z",
            "SIGMA", "GAMMA", "MATCH", "STATUS_FLAG"]
    rows = pre + [",".join(head)]
    for i, j, X in points():
        sid = i * N + j
        x = deform(X)
        u = [x[k] - X[k] for k in range(3)]
        cx, cy = 200 + 20 * j, 640 - 20 * i
        if sid in (6, 30, 40):
            stale = [0.37, -0.21, 0.05]
            cells = [str(sid), f"{cx:.4E}", f"{cy:.4E}"] + [f"{v:.6E}" for v in X + stale] + ["-1", "-1", "-1", "8"]
        else:
            sigma = 0.003 + 0.0005 * (sid % 4)
            cells = [str(sid), f"{cx:.4E}", f"{cy:.4E}"] + [f"{v:.6E}" for v in X + u] + \
                    [f"{sigma:.4E}", "2.1000E-05", "0", "0"]
        rows.append(",".join(cells))
    write("dice_solution_10.txt", "\n".join(rows) + "\n")

    # DICe 2-D: subset centres and displacements in image pixels (0.02 mm per pixel), no
    # z, ' ' as the delimiter (DICe's default output_delimiter). The deformation is the
    # in-plane part only: x = Rz(20 deg) (1.10 X, 0.95 Y) + (2, -1). Subsets 0 and 24
    # failed: SIGMA = -1, MATCH = -1, stale displacements.
    pre = ["***",
           "*** DICe-style 2-D solution file, written by hand for gsa's tests (made-up numbers)",
           "*** Subset size: 25",
           "*** Step size: x 250 y 250 (-1 implies not regular grid)",
           "***"]
    head = ["SUBSET_ID", "COORDINATE_X", "COORDINATE_Y", "DISPLACEMENT_X", "DISPLACEMENT_Y", "SIGMA", "MATCH"]
    rows = pre + [" ".join(head)]
    px = 0.02
    c, sn = math.cos(math.radians(20.0)), math.sin(math.radians(20.0))
    for i, j, X in points():
        sid = i * N + j
        xc = [c * 1.10 * X[0] - sn * 0.95 * X[1] + 2.0, sn * 1.10 * X[0] + c * 0.95 * X[1] - 1.0]
        cx, cy = 1000 + X[0] / px, 1000 + X[1] / px
        if sid in (0, 24):
            cells = [str(sid), f"{cx:.7E}", f"{cy:.7E}", "1.2500000E+01", "-3.0000000E+00", "-1", "-1"]
        else:
            cells = [str(sid), f"{cx:.7E}", f"{cy:.7E}", f"{(xc[0] - X[0]) / px:.7E}", f"{(xc[1] - X[1]) / px:.7E}",
                     "3.0000E-03", "0"]
        rows.append(" ".join(cells))
    write("dice_2d_pixels.txt", "\n".join(rows) + "\n")

    # A plain table without an id column, in metres, with reference positions and
    # displacements under other names (the --columns example of docs/usage.md).
    rows = ["X0 [m],Y0 [m],Z0 [m],ux [m],uy [m],uz [m]"]
    for i, j, X in points():
        x = deform(X)
        u = [x[k] - X[k] for k in range(3)]
        rows.append(",".join(f"{v / 1000:.9f}" for v in X + u))
    write("plain_no_id_metres.csv", "\n".join(rows) + "\n")

    # Grid indices and current positions only: the reference comes from the pitch.
    rows = ["# grid row i (along Y), column j (along X); pitch 5 mm", "i,j,x,y,z"]
    for i, j, X in points():
        rows.append(",".join([str(i), str(j)] + [f6(v) for v in deform(X)]))
    write("grid_indices.csv", "\n".join(rows) + "\n")

    # One file with a stage column: stage 0 is the reference.
    rows = ["id,stage,x,y,z"]
    for t in (0.0, 5.0, 10.0):
        for i, j, X in points():
            rows.append(",".join([f"m{i}_{j}", f"{t:g}"] + [f6(v) for v in deform(X, t)]))
    write("stage_column.csv", "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
