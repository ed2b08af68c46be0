# Installs and enables hedge in the running Blender as a user of that version would, for the
# tests, the demo and scripts/install_blender (imported by path: this file is not part of the
# package):
#   Blender 3.4-4.1  the legacy add-on zip, Preferences > Add-ons > Install (addon_install)
#   Blender 4.2+     the extension zip, Install from Disk: `blender --command extension
#                    install-file -r user_default -e ZIP`, run as a separate Blender
# Files land under the user's folder ($HOME/.config/blender/<version>/...): give tests a
# private HOME.
import importlib
import os
import subprocess

import addon_utils
import bpy

EXTENSIONS = bpy.app.version >= (4, 2, 0)
REPOSITORY = "user_default"
# The name Blender imports the package under.
MODULE = f"bl_ext.{REPOSITORY}.hedge" if EXTENSIONS else "hedge"


def package_for_this_blender(addon_zip, extension_zip):
    """The zip a user of the running Blender installs."""
    path = extension_zip if EXTENSIONS else addon_zip
    if not path or not os.path.exists(path):
        kind = "extension" if EXTENSIONS else "legacy add-on"
        raise RuntimeError(f"Blender {bpy.app.version_string} needs hedge's {kind} zip, which is missing ({path!r})")
    return os.path.abspath(path)


def install(zip_path):
    """Installs the zip, enables the add-on and returns the hedge package."""
    zip_path = os.path.abspath(zip_path)
    if EXTENSIONS:
        done = subprocess.run([bpy.app.binary_path, "--command", "extension", "install-file", "-r", REPOSITORY,
                               "-e", zip_path], capture_output=True, text=True, timeout=300)
        if done.returncode != 0:
            raise RuntimeError(f"extension install-file failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
        # The other Blender installed it: this one looks at its repository again.
        addon_utils.extensions_refresh()
    else:
        bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
        addon_utils.modules_refresh()
    importlib.invalidate_caches()  # a folder listed before the install (a first look) is listed anew
    return enable()


def enable(quiet=False):
    """Enables the installed add-on; returns the package (raises when it does not enable;
    `quiet`: without Blender printing why, for a first look whether it is installed)."""
    module = addon_utils.enable(MODULE, default_set=True, handle_error=(lambda e: None) if quiet else None)
    if module is None:
        raise RuntimeError(f"the hedge add-on ({MODULE}) did not enable")
    return module


def installed_folder():
    """Where the installed package's files are."""
    if EXTENSIONS:
        return os.path.join(bpy.utils.user_resource('EXTENSIONS'), REPOSITORY, "hedge")
    return os.path.join(bpy.utils.user_resource('SCRIPTS'), "addons", "hedge")
