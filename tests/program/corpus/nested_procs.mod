MODULE NestedProcs
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pC := [[300, -150, 400], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        Cell;
        MoveJ pA, v1000, fine, tool0;
    ENDPROC
    PROC Cell()
        Station1;
        Station2;
    ENDPROC
    PROC Station1()
        MoveJ pB, v1000, z20, tool0;
        Grip;
    ENDPROC
    PROC Station2()
        MoveJ pC, v1000, z20, tool0;
        Grip;
    ENDPROC
    PROC Grip()
        WaitTime 0.2;
        SetDO doGrip, 1;
    ENDPROC
ENDMODULE
