# nbgrader settings the worksheets need: copy this file into your course directory (beside source/).
c = get_config()  # noqa: F821 - nbgrader defines it when it reads this file

# A released answer cell keeps its starting line (answer_1 = None, or the program to edit) and gets this
# comment instead of the teacher's answer; the default stub raises NotImplementedError, which would stop
# a student's run of the whole worksheet at the first exercise.
c.ClearSolutions.code_stub = {"python": "# your answer: change the line above, then run this cell and the check below"}
