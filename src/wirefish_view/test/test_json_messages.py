# SPDX-License-Identifier: Apache-2.0
"""JSON Schema from ROS types, and requests filled strictly from JSON."""

import pytest
from std_srvs.srv import Trigger
from wirefish_msgs.action import RetuneGait
from wirefish_view.errors import RefusedInput
from wirefish_view.json_messages import from_json, json_schema


def test_the_goals_schema_has_its_fields_types_and_ranges():
    schema = json_schema(RetuneGait.Goal)
    assert schema['additionalProperties'] is False
    assert schema['properties']['wave']['properties']['c1'] == {'type': 'number'}
    assert schema['properties']['seed'] == {'type': 'integer', 'minimum': 0,
                                            'maximum': 2**32 - 1}
    assert schema['properties']['use_library'] == {'type': 'boolean'}
    result = json_schema(RetuneGait.Result)['properties']
    assert result['rmse_theta_deg'] == {'type': 'array', 'items': {'type': 'number'},
                                        'minItems': 2, 'maxItems': 2}


def test_a_request_fills_the_message_and_keeps_the_types_defaults():
    goal = from_json(RetuneGait.Goal, b'{"wave": {"c1": 0.1, "k": 6}, "apply": true}')
    assert (goal.wave.c1, goal.wave.k, goal.apply, goal.use_library) == (0.1, 6.0, True, True)
    assert from_json(Trigger.Request, b'') == Trigger.Request()
    assert from_json(Trigger.Request, b' {} ') == Trigger.Request()


@pytest.mark.parametrize('payload, reason', [
    (b'{nope', 'not JSON'),
    (b'[1]', 'request must be a JSON object'),
    (b'{"wave": {"c1": "abc"}}', 'wave.c1 must be a finite number, got "abc"'),
    (b'{"wave": {"c1": null}}', 'wave.c1 must be a finite number, got null'),
    (b'{"apply": 1}', 'apply must be true or false'),
    (b'{"max_iterations": -1}', 'max_iterations must be a whole number in [0, 4294967295]'),
    (b'{"seed": 1.5}', 'seed must be a whole number'),
    (b'{"wave": {"c3": 1}}', 'wave: no field c3'),
    (b'{"nope": 1}', 'request: no field nope')])
def test_a_bad_request_is_refused_with_the_reason(payload, reason):
    with pytest.raises(RefusedInput) as refused:
        from_json(RetuneGait.Goal, payload)
    assert reason in str(refused.value)
