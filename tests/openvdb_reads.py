"""OpenVDB's own reader on a `.vdb` that `cumulus export` wrote, against
the `.vol` of the same grid (tests/exports.rs runs it when OpenVDB's
Python binding is installed: `apt-get install python3-openvdb`).

    python3 tests/openvdb_reads.py clouds.vdb clouds.vol

Checks the grid's name, class and type, its statistics metadata, that its voxels are the volume's
values exactly (inactive ones at the background 0), that the active
voxels are the cloudy cells, and that the transform takes index (i, j, k)
to cell (i, j, k)'s centre. Exits non-zero with the reason otherwise.
"""
import struct
import sys

import numpy as np

try:  # OpenVDB 10 (Debian 12's python3-openvdb) names its module pyopenvdb,
    import pyopenvdb as vdb
except ImportError:  # later versions openvdb
    import openvdb as vdb


def main(vdb_path, vol_path):
    grids, meta = vdb.readAll(vdb_path)
    assert [g.name for g in grids] == ["density"], [g.name for g in grids]
    g = grids[0]
    assert g.gridClass == "fog volume", g.gridClass
    assert g.valueTypeName == "float", g.valueTypeName
    assert g.background == 0.0, g.background
    b = open(vol_path, "rb").read()
    nx, ny, nz = struct.unpack("<3i", b[8:20])
    lo = np.array(struct.unpack("<3f", b[24:36]), dtype=np.float64)
    hi = np.array(struct.unpack("<3f", b[36:48]), dtype=np.float64)
    vol = np.frombuffer(b[48:], dtype="<f4").reshape(nz, ny, nx).transpose(2, 1, 0)
    dense = np.zeros((nx, ny, nz), dtype=np.float32)
    g.copyToArray(dense, ijk=(0, 0, 0))
    assert np.array_equal(dense, vol), f"values differ by up to {np.abs(dense - vol).max()}"
    active = int((vol > 0).sum())
    assert g.activeVoxelCount() == active, (g.activeVoxelCount(), active)
    # The statistics OpenVDB's own writer adds, which Houdini and
    # vdb_print show without reading the voxels.
    m = g.metadata
    assert m["file_voxel_count"] == active, m
    lo_ijk, hi_ijk = g.evalActiveVoxelBoundingBox()
    assert tuple(m["file_bbox_min"]) == tuple(lo_ijk), (m, lo_ijk)
    assert tuple(m["file_bbox_max"]) == tuple(hi_ijk), (m, hi_ijk)
    assert m["file_compression"] == "zip" and m["is_saved_as_half_float"] is False, m
    cell = (hi - lo) / np.array([nx, ny, nz])
    for ijk in [(0, 0, 0), (nx - 1, ny - 1, nz - 1), (nx // 2, ny // 3, nz // 5)]:
        world = np.array(g.transform.indexToWorld(ijk))
        centre = lo + (np.array(ijk) + 0.5) * cell
        assert np.abs(world - centre).max() < 1e-2, (ijk, world, centre)
    print(f"OpenVDB {'.'.join(map(str, vdb.LIBRARY_VERSION))} read {vdb_path}: "
          f"{nx}x{ny}x{nz}, {active} active voxels, equal to {vol_path}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
