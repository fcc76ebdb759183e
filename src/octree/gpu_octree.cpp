// placeholder: implemented in the stage's work
