"""Shared fixtures of the CFD tests: devices to run kernels on (cuda only when present)."""

import pytest
import warp as wp

wp.config.quiet = True


def _devices():
    devs = [pytest.param("cpu", id="cpu")]
    devs.append(pytest.param("cuda", id="cuda", marks=[
        pytest.mark.cuda,
        pytest.mark.skipif(not wp.is_cuda_available(), reason="no CUDA device")]))
    return devs


DEVICES = _devices()
