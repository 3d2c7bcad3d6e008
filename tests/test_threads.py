"""The batched kernels run with one BLAS thread by default; code outside
them keeps the BLAS default."""
import pytest
from threadpoolctl import threadpool_info

from skfem_pg import threads


def _blas_threads():
    """Threads of the BLAS libraries the kernels limit: those loaded when
    the first kernel ran (NumPy's); a BLAS loaded later by another package
    (MKL with pypardiso, whose PARDISO keeps its threads) is not
    limited."""
    mine = {c.filepath for c in threads._limiter().lib_controllers
            if c.user_api == "blas"}
    return [i["num_threads"] for i in threadpool_info()
            if i["user_api"] == "blas" and i["filepath"] in mine]


def test_kernels_limit_blas_threads_and_restore_them():
    outside = _blas_threads()

    @threads.kernel
    def probe():
        return _blas_threads()

    @threads.kernel
    def nested():
        return probe(), _blas_threads()

    old = threads.set_kernel_threads(1)
    try:
        assert all(n == 1 for n in probe())
        inner, outer = nested()
        assert all(n == 1 for n in inner + outer)
        assert _blas_threads() == outside
        threads.set_kernel_threads("default")
        assert probe() == outside
    finally:
        threads.set_kernel_threads(old)
    assert "BLAS threads in skfem_pg kernels" in threads.describe()


@pytest.mark.parametrize("bad", [0, -2, "many", 1.5j])
def test_bad_settings_raise(bad):
    with pytest.raises(ValueError, match="positive integer|>= 1"):
        threads.set_kernel_threads(bad)
