"""Loading the PenumbraShadows plugin from pvpython, pvbatch or the GUI's Python shell, on the
client and on the server, whether or not a process has it already; and what its view sent
between MPI ranks (exchange_report); a scene file's shadow settings applied to a view
(apply_scene_settings).

    from paraview.simple import *
    Connect("localhost", 11111)                  # or no Connect: the built-in session
    import penumbra_paraview
    penumbra_paraview.load_plugin(ns=globals())  # then CreateView("PenumbraShadowView")

Why not ``LoadPlugin(path, remote=True)`` alone: when the server already loaded that file
(from its PV_PLUGIN_PATH), ParaView 5.11's vtkPVPluginLoader returns success without setting
its Loaded flag, and vtkSMPluginManager then reports "Plugin load failed: No plugin loaded
yet." and LoadPlugin raises a RuntimeError. So each process is asked first (its plugin
information) and loaded only if it lacks the plugin.

./penumbra.sh paraview puts this module on PYTHONPATH (beside the penumbra package).
"""
import os

NAME = "PenumbraShadows"


def default_plugin():
    """PenumbraShadows.so in a folder of PV_PLUGIN_PATH, or None."""
    for folder in os.environ.get("PV_PLUGIN_PATH", "").split(os.pathsep):
        path = os.path.join(folder, NAME + ".so")
        if folder and os.path.isfile(path):
            return path
    return None


def _loaded(information):
    return any(information.GetPluginName(i) == NAME and information.GetPluginLoaded(i)
               for i in range(information.GetNumberOfPlugins()))


def load_plugin(plugin=None, ns=None):
    """Loads the plugin (`plugin`: the .so's path, on the server's file system for the server;
    default default_plugin()) where it is missing: on this process, and on the server when
    the active connection is remote. `ns`: the namespace to refresh (the script's globals()),
    as for paraview.simple.LoadPlugin. Returns the list of where it was loaded ("client",
    "server"), empty when every process had it. Raises RuntimeError when a load fails or no
    path is known."""
    from paraview import servermanager, simple

    connection = servermanager.ActiveConnection
    if connection is None:
        raise RuntimeError("load_plugin needs a session: Connect() first, or run in pvpython")
    manager = servermanager.vtkSMProxyManager.GetProxyManager().GetPluginManager()
    missing = []
    if not _loaded(manager.GetLocalInformation()):
        missing.append("client")
    if connection.IsRemote() and not _loaded(manager.GetRemoteInformation(connection.Session)):
        missing.append("server")
    plugin = plugin or default_plugin()
    if missing and not plugin:
        raise RuntimeError("no %s.so: pass its path or set PV_PLUGIN_PATH" % NAME)
    for where in missing:
        simple.LoadPlugin(plugin, remote=(where == "server"), ns=ns)
    if not missing and ns is not None:
        simple.LoadPlugins(ns=ns)  # nothing to load; refreshes `ns` as LoadPlugin would
    return missing


def exchange_report(view):
    """What distributed rendering sent between the ranks for `view` (a PenumbraShadowView), as
    text: a line per rank of the last caster exchange (own casters, other ranks' triangles
    held, triangles and bytes sent, bytes received, peers, the time of each step) and, with
    CasterExchange "distributed", of the last frame's ray queries. From the render server's
    first rank in client/server mode, from this rank under pvbatch --symmetric (rank 0 has
    every rank's lines); "" before a distributed render.

        print(penumbra_paraview.exchange_report(view))
    """
    view.UpdatePropertyInformation()
    return view.GetProperty("CasterExchangeReport").GetData()


def apply_scene_settings(view, path):
    """Applies a Penumbra scene file's shadow settings to `view` (a PenumbraShadowView): its
    "technique" block (ShadowTechnique, and the block's options as ShadowOptions) and its
    "distributed" block (CasterExchange, CasterMemoryBudget: how MPI ranks share their
    casters; Data/Scenes/SCHEMA.md). The scene's objects, lights and camera are neither read
    nor needed: the pipeline is ParaView's. The blocks are checked by vtkPenumbraSceneReader
    (SettingsOnly), as penumbra-render checks them: a bad one raises ValueError with the
    reader's message (file, field, problem) and changes nothing.

        penumbra_paraview.apply_scene_settings(view, "city.json")
    """
    import json

    from penumbra.vtkPenumbraSceneIO import vtkPenumbraSceneReader

    reader = vtkPenumbraSceneReader()
    reader.SettingsOnlyOn()
    reader.SetFileName(path)
    reader.AddObserver("ErrorEvent", lambda *args: None)  # raised below, not printed
    if not reader.Read():
        raise ValueError(reader.GetErrorMessage())
    options = reader.GetTechniqueOptions()
    view.ShadowTechnique = reader.GetTechniqueName()
    view.ShadowOptions = "" if json.loads(options) == {} else options
    view.CasterExchange = reader.GetCasterExchange()
    view.CasterMemoryBudget = reader.GetCasterMemoryBudget()
