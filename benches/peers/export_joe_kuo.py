"""Writes the Joe-Kuo D6 direction numbers that impactcal-core ships.

The table (Joe & Kuo 2008, file new-joe-kuo-6.21201) is read from the copy that scipy
installs (scipy/stats/_sobol_direction_numbers.npz: `poly` holds each primitive polynomial
with its leading and trailing 1 bits, `vinit` the initial direction numbers m_1..m_s).
Each output line describes one dimension from the second on: `s a m_1 ... m_s`, the format
of the original file without its dimension column.

Usage: benches/peers/.venv/bin/python benches/peers/export_joe_kuo.py 2048 > \
    crates/impactcal-core/src/sampling/joe_kuo_d6.txt
"""

import pathlib
import sys

import numpy as np
import scipy

HEADER = """\
# Sobol' direction numbers of Joe and Kuo (2008), search criterion D6, dimensions 2..{dims}.
# Source: new-joe-kuo-6.21201, https://web.maths.unsw.edu.au/~fkuo/sobol/ (as shipped by scipy).
# Line k (k = 1, 2, ...) describes dimension k + 1: degree s, polynomial coefficients a,
# initial direction numbers m_1 .. m_s.
#
# Copyright (c) 2008, Frances Y. Kuo and Stephen Joe. All rights reserved.
# Redistribution and use in source and binary forms, with or without modification, are
# permitted provided that the following conditions are met:
# * Redistributions of source code must retain the above copyright notice, this list of
#   conditions and the following disclaimer.
# * Redistributions in binary form must reproduce the above copyright notice, this list of
#   conditions and the following disclaimer in the documentation and/or other materials
#   provided with the distribution.
# * Neither the names of the copyright holders nor the names of the University of New South
#   Wales and the University of Waikato and its contributors may be used to endorse or
#   promote products derived from this software without specific prior written permission.
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS "AS IS" AND ANY EXPRESS OR IMPLIED
# WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE IMPLIED WARRANTIES OF MERCHANTABILITY AND
# FITNESS FOR A PARTICULAR PURPOSE ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDERS
# BE LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR CONSEQUENTIAL
# DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR SERVICES; LOSS
# OF USE, DATA, OR PROFITS; OR BUSINESS INTERRUPTION) HOWEVER CAUSED AND ON ANY THEORY OF
# LIABILITY, WHETHER IN CONTRACT, STRICT LIABILITY, OR TORT (INCLUDING NEGLIGENCE OR
# OTHERWISE) ARISING IN ANY WAY OUT OF THE USE OF THIS SOFTWARE, EVEN IF ADVISED OF THE
# POSSIBILITY OF SUCH DAMAGE."""


def main() -> None:
    dims = int(sys.argv[1])
    path = pathlib.Path(scipy.__file__).parent / "stats" / "_sobol_direction_numbers.npz"
    table = np.load(path)
    poly, vinit = table["poly"], table["vinit"]
    print(HEADER.format(dims=dims))
    for d in range(1, dims):
        p = int(poly[d])
        s = p.bit_length() - 1
        a = (p >> 1) & ((1 << (s - 1)) - 1)
        print(s, a, *(int(m) for m in vinit[d, :s]))


if __name__ == "__main__":
    main()
