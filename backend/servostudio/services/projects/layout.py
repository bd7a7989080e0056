"""Names of the files and directories of the project store (documented in docs/projects.md)."""

PROJECT_FILE = "project.toml"
SEQUENCE = "SEQUENCE.TXT"
CAPTURES_DIR = "captures"  # <axis>/captures/NAME.csv + NAME.json: saved oscilloscope captures (docs/scope.md)
PROCEDURES_DIR = "procedures"  # <axis>/procedures/NAME-TIME.json: results of phasing, tuning… (docs/commissioning.md)
FREQUENCY_DIR = "frequency"  # <axis>/frequency/NAME.csv + NAME.json: frequency responses (docs/frequency-response.md)
USER_MOTORS_DIR = ".motors"  # user motor catalog inside the project store (names never start with '.')
TEMP_PREFIX = "."  # temporary files and directories start with a dot and are never listed
