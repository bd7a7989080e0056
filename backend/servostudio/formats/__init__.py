"""formats layer: the drives' own text files, parsed and written without the object dictionary.

- ``objectfile``  DRIVEPAR.TXT / USER_PAR.TXT (``index,sub=value`` lines)
- ``sequence``    SEQUENCE.TXT (model in ``sequence_model``, keyword tables in ``sequence_spec``,
  ``sequence_reader``, ``sequence_writer``)
- ``numbers``, ``textfile``  shared number syntax, encoding, line splitting, atomic writes

See docs/file-formats.md.
"""
