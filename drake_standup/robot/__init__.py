"""The iCub from icub-models made Drake-ready: the model and its meshes."""
