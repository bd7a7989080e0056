"""Device profiles: what differs between drive families, keyed by semantic names.

Services ask a profile for ``"statusword"`` or the ``"save"`` signature instead of writing 0x6041 or 0x65766173;
a new device family is a new profile module, not edits all over the services.
"""

from __future__ import annotations

from servostudio.drive.profiles.base import DeviceProfile, ProfileError, generic_profile, signature_value
from servostudio.drive.profiles.cd1k import CD1K
from servostudio.drive.profiles.encotrive import ENCOTRIVE
from servostudio.drive.profiles.ttapro import TTAPRO
from servostudio.drive.profiles.xtrapulspac import XTRAPULSPAC

PROFILES: dict[str, DeviceProfile] = {profile.device: profile for profile in (XTRAPULSPAC, CD1K, ENCOTRIVE, TTAPRO)}


def profile_for(device: str | None) -> DeviceProfile:
    """The profile of a device key; devices without one get the plain CiA 301/402 profile."""
    return PROFILES.get(device or "", generic_profile(device or "unknown"))


__all__ = ["PROFILES", "DeviceProfile", "ProfileError", "profile_for", "signature_value"]
