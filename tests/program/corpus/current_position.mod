MODULE CurrentPosition
    ! The cycle starts where it ends: the first move goes to the current position.
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget jWork := [[40, 10, 10, 0, 40, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveAbsJ jHome, v1000, fine, tool0;
        MoveAbsJ jWork, v1000, z50, tool0;
        MoveAbsJ jHome, v1000, fine, tool0;
    ENDPROC
ENDMODULE
