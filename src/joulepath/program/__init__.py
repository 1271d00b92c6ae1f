"""Robot programs: read a RAPID module (or a plain cycle file), run its cycle as the controller does, optimize it."""
