"""Object dictionaries: CiA 306 EDS + companion `.props` -> `ObjectDictionary`; CiA 301 data types; EDS library.

See docs/eds.md for the file formats.
"""

from servostudio.od.datatypes import DataType, EncodingError, decode, encode
from servostudio.od.eds import load_dictionary, parse_dictionary
from servostudio.od.library import BUILTIN_EDS_DIR, EdsLibrary, LibraryError, builtin_library
from servostudio.od.model import (
    Access,
    BitField,
    DictionaryError,
    DictObject,
    ObjectDictionary,
    ObjectKind,
    OutOfRange,
    SaveType,
    Variable,
    WrongType,
)
from servostudio.od.pointer import Pointer

__all__ = [
    "BUILTIN_EDS_DIR",
    "Access",
    "BitField",
    "DataType",
    "DictObject",
    "DictionaryError",
    "EdsLibrary",
    "EncodingError",
    "LibraryError",
    "ObjectDictionary",
    "ObjectKind",
    "OutOfRange",
    "Pointer",
    "SaveType",
    "Variable",
    "WrongType",
    "builtin_library",
    "decode",
    "encode",
    "load_dictionary",
    "parse_dictionary",
]
