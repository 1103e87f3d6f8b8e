"""The checks of what a user sets, on the lowest floor so that every kind (specimen, model, law, experiment,
method) can read and check its own table: :class:`~fracid.settings.checks.SettingError` and the checkers
whose messages name the key, the value and what is allowed (:mod:`~fracid.settings.checks`), and
:class:`~fracid.settings.field_error.FieldError`, an invalid named field or parameter.

Imports nothing of fracid.
"""
