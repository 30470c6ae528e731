# Sourced by scripts/install.sh and scripts/uninstall.sh: where the two installed files go.
# The site folder is that of Debian's /usr/bin/python3 (the interpreter Blender embeds), so a
# .pth there reaches it, venvs made from it with --system-site-packages, and Blender.
# AOLAB_INSTALL_PREFIX (default /usr/local) lets the tests install into a scratch folder.
aolab_prefix="${AOLAB_INSTALL_PREFIX:-/usr/local}"
aolab_site="$aolab_prefix/lib/$(/usr/bin/python3 -c 'import sys; print(f"python3.{sys.version_info.minor}")')/dist-packages"
aolab_pth="$aolab_site/aolab.pth"
aolab_command="$aolab_prefix/bin/aolab"
# The first line of the command marks it as ours; uninstall removes only a file carrying it.
aolab_marker="# aolab command installed by AO Lab scripts/install.sh"
AOLAB_SUDO=""
[ "$(id -u)" -eq 0 ] || [ -w "$aolab_prefix" ] || AOLAB_SUDO="sudo"
