# Reference EDFs from Python allantools' edf_greenhall() (Greenhall & Riley,
# PTTI 2003) on a grid, for tests/testthat/test-ci-exact.R. allantools is
# not part of this repository: point ALLANTOOLS_PATH at a checkout (its
# allantools/ci.py is imported) and run with a Python that has numpy and
# scipy (Debian: python3-numpy, python3-scipy), from the repository root:
#   ALLANTOOLS_PATH=/tmp/allantools /usr/bin/python3 \
#     tools/make-greenhall-fixture.py > tests/testthat/fixtures/edf-greenhall.csv
import os
import sys

sys.path.insert(0, os.environ.get("ALLANTOOLS_PATH", "/tmp/allantools"))
from allantools import ci  # noqa: E402

# allan()'s types: (name, d, overlapping, modified)
types = [("standard", 2, False, False), ("overlapping", 2, True, False),
         ("modified", 2, True, True), ("hadamard", 3, False, False),
         ("ohadamard", 3, True, False)]
ms = [1, 2, 3, 4, 7, 8, 16, 33, 64, 100, 256, 1000]
Ns = [10, 33, 101, 1000, 10001, 100000]
print("type,alpha,m,N,edf")
for name, d, ov, mod in types:
    for alpha in range(2, -5, -1):
        if alpha + 2 * d <= 1:
            continue
        for N in Ns:
            for m in ms:
                L = m + m * d if not mod else 1 + m * d
                if N < L + 1:
                    continue
                try:
                    e = ci.edf_greenhall(alpha, d, m, N, overlapping=ov,
                                         modified=mod)
                except (NotImplementedError, AssertionError):
                    # allantools has no value (alpha = 2 with r <= d;
                    # its Table 2 stops at alpha = -2)
                    continue
                if e <= 0:  # allantools' -1: no terms
                    continue
                print("%s,%d,%d,%d,%.12g" % (name, alpha, m, N, float(e)))
