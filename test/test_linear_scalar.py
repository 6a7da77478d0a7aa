# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""The linear theory's plain-float paths against the vectorised ones."""

from football_ros.physics import dynamics as dyn
from football_ros.physics import get_preset
from football_ros.physics import linear_theory as lt
from football_ros.physics.aero import AeroModel, resolve
import numpy as np
import pytest


def kernel_params(ball: str, model: str) -> np.ndarray:
    preset, aero = resolve(get_preset(ball), model, AeroModel() if model == 'full' else None)
    return dyn.make_params(preset, 'linear', aero)


@pytest.mark.parametrize('ball', ['american', 'rugby'])
@pytest.mark.parametrize('model', ['paper', 'full'])
def test_drifting_equilibrium_scalar(ball, model):
    params = kernel_params(ball, model)
    consts = lt.scalar_constants(params)
    rng = np.random.default_rng(11)
    air = rng.normal(size=(200, 3)) * 8.0 + np.array([22.0, 0.0, 6.0])
    h1 = rng.uniform(20.0, 150.0, 200) * rng.choice([-1.0, 1.0], 200)
    _, _, b_v, d_v, x_v = lt.local_exponents(params, air, h1)
    vec = lt.drifting_equilibrium(lambda a, h: lt.local_exponents(params, a, h), consts, air,
                                  h1, b_v, d_v, x_v)
    for i in range(len(h1)):
        _, _, b, d_c, x_p = lt.local_exponents_scalar(consts, air[i], float(h1[i]))
        got = lt.drifting_equilibrium_scalar(consts, air[i], float(h1[i]), b, d_c, x_p)
        # The same operations as the generic function fed the scalar exponents: equal.
        assert got == lt.drifting_equilibrium(
            lambda a, h: lt.local_exponents_scalar(consts, a, float(h)), consts, air[i],
            float(h1[i]), b, d_c, x_p)
        # Against the vectorised exponents (their round-off differs from the scalar one's at
        # 1e-16, and the central difference, step 1e-4 s, magnifies it in x_p'): near.
        assert abs(got[0] - vec[0][i]) <= 1e-9 * abs(got[0]) + 1e-12
        assert abs(got[1] - vec[1][i]) <= 1e-6 * abs(got[1]) + 1e-9
