MODULE InPosIdle
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PERS num nOperator := 2.0;
    PROC main()
        WHILE TRUE DO
            MoveJ pA, v1000, z50, tool0;
            MoveL pB, v300, z10, tool0;
            WaitTime \InPos, 0.5;
            MoveJ pA, v1000, fine, tool0;
            ! joulepath: idle
            WaitTime nOperator;
            WaitTime 0; ! joulepath: idle
        ENDWHILE
    ENDPROC
ENDMODULE
