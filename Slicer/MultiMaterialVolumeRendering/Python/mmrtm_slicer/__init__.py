"""3D Slicer's Volume Rendering with the MM-RTM path tracer.

The classes of the Slicer extension MultiMaterialVolumeRendering, built for
the PyPI Slicer core (slicer-core, slicer-layer-dm, vtk 9.6):
vtkMRMLMultiMaterialVolumeRenderingDisplayNode (the display node),
vtkSlicerMultiMaterialVolumeRenderingLogic (the rendering method "Path
tracing (MM-RTM)") and vtkMRMLMultiMaterialVolumeRenderingPipeline (the
LayerDM pipeline that renders the node in 3D views; importing this package
registers its creator, and a factory that lets any scene create the display
node by class name). They are also reachable as `from slicer import ...`.
"""
# The libraries and Python types of the classes ours derive from first.
import slicer_core  # noqa: F401
import slicer_layer_dm  # noqa: F401
import mmrtm  # noqa: F401

from .vtkSlicerMultiMaterialVolumeRenderingModuleMRML import *  # noqa: F401,F403
from .vtkSlicerMultiMaterialVolumeRenderingModuleLogic import *  # noqa: F401,F403
from .vtkSlicerMultiMaterialVolumeRenderingModuleMRMLDisplayableManager import *  # noqa: F401,F403

vtkMRMLMultiMaterialVolumeRenderingPipeline.RegisterPipelineCreator()  # noqa: F405
# Any scene can then create the display node by class name, so that Volume
# Rendering's logic set to this method before this module's logic is
# registered (trame-slicer) makes the node instead of crashing.
vtkMRMLMultiMaterialVolumeRenderingDisplayNode.RegisterNodeFactory()  # noqa: F405
