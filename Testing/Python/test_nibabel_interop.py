"""Files Repose writes read back identically with nibabel, a reader we did not write, and files
nibabel writes read identically in Repose: same voxels, same affine, same axis codes."""
import json

import nibabel as nib
import numpy as np
import pytest


def oblique_affine():
    angle = 0.4
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    aff = np.eye(4)
    aff[:3, :3] = rot @ np.diag([1.3, 1.3, 7.2])
    aff[:3, 3] = [-120.5, 33.25, -804.5]
    return aff


@pytest.mark.parametrize("ext", [".nii", ".nii.gz"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.int32, np.float32])
def test_nibabel_file_reads_identically_in_repose(tmp_path, repose, ext, dtype):
    rng = np.random.default_rng(7)
    data = rng.integers(0, 200, size=(13, 9, 5)).astype(dtype)
    src = tmp_path / f"src{ext}"
    nib.save(nib.Nifti1Image(data, oblique_affine()), src)
    out = tmp_path / "back.nii"
    repose("convert", src, out)
    back = nib.load(out)
    assert back.get_data_dtype() == np.dtype(dtype)
    np.testing.assert_array_equal(np.asarray(back.dataobj), data)
    np.testing.assert_allclose(back.affine, oblique_affine(), atol=1e-4)
    info = json.loads(repose("info", src, "--json").stdout)
    np.testing.assert_allclose(np.array(info["ijk_to_ras"]), oblique_affine(), atol=1e-4)
    assert info["orientation"] == "".join(nib.aff2axcodes(oblique_affine()))


@pytest.mark.parametrize("version", ["1", "2"])
def test_repose_writes_both_nifti_versions_that_nibabel_reads(tmp_path, repose, data_dir, version):
    src = data_dir / "totalsegmentator" / "example_seg.nii.gz"
    out = tmp_path / f"seg_v{version}.nii.gz"
    repose("convert", src, out, "--nifti-version", version)
    ref, ours = nib.load(src), nib.load(out)
    assert isinstance(ours, nib.Nifti2Image if version == "2" else nib.Nifti1Image)
    np.testing.assert_array_equal(np.asarray(ours.dataobj), np.asarray(ref.dataobj))
    np.testing.assert_allclose(ours.affine, ref.affine, atol=1e-4)
    assert int(ours.header["sform_code"]) > 0 and int(ours.header["qform_code"]) > 0
    # The label names travel in the same Caret XML extension TotalSegmentator uses.
    xml = b"".join(e.get_content() for e in ours.header.extensions)
    assert b"<![CDATA[liver]]>" in xml or b">liver</Label>" in xml


def test_segnrrd_chain_matches_nibabel_reference(tmp_path, repose, data_dir):
    src = data_dir / "totalsegmentator" / "example_seg.nii.gz"
    seg = tmp_path / "seg.seg.nrrd"
    back = tmp_path / "back.nii.gz"
    repose("convert", src, seg)
    repose("convert", seg, back)
    ref, ours = nib.load(src), nib.load(back)
    np.testing.assert_array_equal(np.asarray(ours.dataobj), np.asarray(ref.dataobj))
    np.testing.assert_allclose(ours.affine, ref.affine, atol=1e-4)


def test_dicom_series_as_nifti_matches_the_reference_segmentation_grid(tmp_path, repose, data_dir):
    out = tmp_path / "ct.nii.gz"
    repose("convert", data_dir / "totalsegmentator" / "example_ct_dicom_j2k", out)
    ct = nib.load(out)
    seg = nib.load(data_dir / "totalsegmentator" / "example_seg_dicom.nii.gz")
    # Same physical grid up to the documented j flip and slice order: compare voxel centres.
    ijk = np.array([[0, 0, 0, 1], [511, 511, 19, 1], [100, 200, 5, 1]]).T
    ras = ct.affine @ ijk
    seg_ijk = np.linalg.solve(seg.affine, ras)
    np.testing.assert_allclose(seg_ijk[0], ijk[0], atol=1e-3)
    np.testing.assert_allclose(seg_ijk[1], 511 - ijk[1], atol=1e-3)
    assert np.allclose(seg_ijk[2], np.round(seg_ijk[2]), atol=1e-3)


def test_info_orientation_codes_agree_with_nibabel_on_real_files(repose, data_dir):
    for name in ["example_seg.nii.gz", "example_mr_sm.nii.gz", "example_seg_dicom.nii.gz"]:
        path = data_dir / "totalsegmentator" / name
        info = json.loads(repose("info", path, "--json").stdout)
        img = nib.load(path)
        assert info["orientation"] == "".join(nib.aff2axcodes(img.affine)), name
        assert info["dimensions"] == list(img.shape[:3])
        np.testing.assert_allclose(info["spacing_mm"], img.header.get_zooms()[:3], rtol=1e-5)
